// A VTK mapper that draws its triangles in the order of its cell array, with no depth test:
// later triangles land on top. Fed with the tree's back-to-front order this is exact
// visibility without a depth buffer (docs/architecture.md, "Drawing with VTK in tree order").
#pragma once

#include <vtkNew.h>
#include <vtkOpenGLPolyDataMapper.h>
#include <vtkPolyData.h>

#include <array>
#include <cstddef>
#include <vector>

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

  // Blending on (the default) or off while drawing; see above.
  void set_blending(bool on) { blending_ = on; }
  bool blending() const { return blending_; }

  // Vertices [first, first + count) of the input changed their positions and colours only
  // (a frame's colour-box faces, TerrainRenderer::set_frame): the next draw writes them into
  // the vertex buffers in place (glBufferSubData), as the input's point and scalar arrays hold
  // them, instead of VTK uploading every vertex again. The caller does not mark those arrays
  // modified (which would upload everything anyway); the range must lie within the vertices
  // VTK last uploaded.
  void update_vertices(std::size_t first, std::size_t count) {
    update_first_ = first;
    update_count_ = count;
  }

  OrderedPolyDataMapper(const OrderedPolyDataMapper&) = delete;
  OrderedPolyDataMapper& operator=(const OrderedPolyDataMapper&) = delete;

 protected:
  OrderedPolyDataMapper() = default;
  ~OrderedPolyDataMapper() override = default;
  void BuildIBO(vtkRenderer* ren, vtkActor* act, vtkPolyData* poly) override;
  void BuildBufferObjects(vtkRenderer* ren, vtkActor* act) override;

 private:
  bool blending_ = true;
  std::size_t update_first_ = 0, update_count_ = 0;
  std::vector<float> packed_;  // update_vertices' positions when VTK shifts and scales them
  bool saved_depth_test_ = true;
  bool saved_blend_ = false;
  std::array<int, 4> saved_blend_func_{};
  vtkNew<vtkPolyData> no_triangles_;  // the input without its triangles, for VTK's other buffers
};

}  // namespace terravol::app::render
