// A VTK mapper that draws its triangles in the order of its cell array, with no depth test:
// later triangles land on top. Fed with the tree's back-to-front order this is exact
// visibility without a depth buffer (docs/architecture.md, "Drawing with VTK in tree order").
#pragma once

#include <vtkNew.h>
#include <vtkOpenGLHelper.h>
#include <vtkOpenGLPolyDataMapper.h>
#include <vtkPolyData.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

class vtkShaderProgram;

namespace terravol::app::render {

// Around its draw the mapper turns the depth test off and blending on
// (src alpha, one minus src alpha for colour; one, one minus src alpha for alpha), through
// vtkOpenGLRenderWindow::GetState(), and restores both afterwards. With set_blending(false)
// blending is off instead: the same image when every fragment is opaque (alpha 1), for less
// work per fragment (about 10% of the terrain's fragment cost on llvmpipe). Use it with
// actor->ForceOpaqueOn() so that VTK draws it in the opaque pass, in the cells' order, instead
// of through its own translucency passes; the renderer must not use depth peeling.
// Props drawn after it (in the same pass) still depth-test against whatever wrote depth
// before; this mapper writes no depth.
// Its index buffer, rebuilt whenever the cell array changes (every frame of a flythrough), is
// the triangles' 32-bit connectivity uploaded as it is, when the input holds only triangles
// with 32-bit ids drawn as surfaces without edges or vertices (outside hardware selection):
// VTK 9.1 walks the cells one by one instead (vtkOpenGLIndexBufferObject::
// AppendTriangleIndexBuffer: 1.3 ms for 49,000 triangles, 11 ms for the 744,000 of a
// full-resolution frame). Otherwise VTK's own path.
class OrderedPolyDataMapper : public vtkOpenGLPolyDataMapper {
 public:
  static OrderedPolyDataMapper* New();
  vtkTypeMacro(OrderedPolyDataMapper, vtkOpenGLPolyDataMapper);

  void RenderPieceStart(vtkRenderer* ren, vtkActor* act) override;
  void RenderPieceFinish(vtkRenderer* ren, vtkActor* act) override;
  void ReleaseGraphicsResources(vtkWindow* win) override;

  // Blending on (the default) or off while drawing; see above.
  void set_blending(bool on) { blending_ = on; }
  bool blending() const { return blending_; }

  // Vertices [first, first + count) of the input changed their positions and colours only
  // (a frame's colour-box faces, TerrainRenderer::set_frame): the next draw writes them into
  // the vertex buffers in place (glBufferSubData), as the input's point and scalar arrays hold
  // them, instead of VTK uploading every vertex again. The caller does not mark those arrays
  // modified (which would upload everything anyway); the range must lie within the vertices
  // VTK last uploaded.
  // Ranges given before one draw are joined (the smallest range holding them all).
  void update_vertices(std::size_t first, std::size_t count) {
    if (count == 0) return;
    join_update(first, count);
  }

  // Runs of triangles (in the cell array's order, counted in triangles) that need no texture:
  // merged pieces, whose colour is their vertices' whatever the texture says. llvmpipe runs
  // both sides of a fragment shader's branch on every fragment (it masks, it does not jump),
  // so in one draw every merged fragment pays the terrain's bilinear texture fetch: about 35
  // ms of a 1280x720 frame of the benchmark's volumes over N44W072. These runs are drawn with a
  // second program instead: VTK's own, built from the same sources with the fragment shader's
  // text between kTextureBegin and kTextureEnd replaced by the vertex colour. The other
  // triangles, and everything when the shader has no such block, take VTK's program. The
  // image is the same: the replaced block gives a merged vertex's colour anyway (its texture
  // coordinates are negative). Each run costs two draw calls and a program switch, so only
  // long runs pay (TerrainRenderer keeps runs of at least kMinUntexturedRun).
  struct Run {
    std::uint32_t first = 0, count = 0;
  };
  static constexpr std::string_view kTextureBegin = "//TERRAVOL::Texture::Begin";
  static constexpr std::string_view kTextureEnd = "//TERRAVOL::Texture::End";
  static constexpr std::uint32_t kMinUntexturedRun = 128;
  // Sorted, disjoint, within the triangles of the next draw (copied; the buffer is kept).
  void set_untextured_runs(std::span<const Run> runs) { untextured_.assign(runs.begin(), runs.end()); }

  OrderedPolyDataMapper(const OrderedPolyDataMapper&) = delete;
  OrderedPolyDataMapper& operator=(const OrderedPolyDataMapper&) = delete;

 protected:
  OrderedPolyDataMapper() = default;
  ~OrderedPolyDataMapper() override = default;
  void BuildIBO(vtkRenderer* ren, vtkActor* act, vtkPolyData* poly) override;
  void BuildBufferObjects(vtkRenderer* ren, vtkActor* act) override;
  void RenderPieceDraw(vtkRenderer* ren, vtkActor* act) override;

 private:
  bool blending_ = true;
  std::size_t update_first_ = 0, update_count_ = 0;
  void join_update(std::size_t first, std::size_t count) {
    if (update_count_ == 0) {
      update_first_ = first;
      update_count_ = count;
      return;
    }
    const std::size_t end = std::max(update_first_ + update_count_, first + count);
    update_first_ = std::min(update_first_, first);
    update_count_ = end - update_first_;
  }
  std::vector<float> packed_;  // update_vertices' positions when VTK shifts and scales them
  bool saved_depth_test_ = true;
  bool saved_blend_ = false;
  std::array<int, 4> saved_blend_func_{};
  vtkNew<vtkPolyData> no_triangles_;  // the input without its triangles, for VTK's other buffers
  bool direct_ = false;                // the last BuildIBO uploaded the triangles as they are

  // The untextured program (see set_untextured_runs), its VAO, and the VTK program it was made from.
  std::vector<Run> untextured_;
  vtkOpenGLHelper plain_;
  vtkShaderProgram* plain_source_ = nullptr;
  bool ready_plain(vtkRenderer* ren, vtkActor* act);
};

}  // namespace terravol::app::render
