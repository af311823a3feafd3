// A VTK mapper that draws its triangles in the order of its cell array, with no depth test:
// later triangles land on top. Fed with the tree's back-to-front order this is exact
// visibility without a depth buffer (docs/architecture.md, "Drawing with VTK in tree order").
#pragma once

#include <vtkOpenGLPolyDataMapper.h>

#include <array>

namespace terravol::app {

// Around its draw the mapper turns the depth test off and blending on
// (src alpha, one minus src alpha for colour; one, one minus src alpha for alpha), through
// vtkOpenGLRenderWindow::GetState(), and restores both afterwards. Use it with
// actor->ForceOpaqueOn() so that VTK draws it in the opaque pass, in the cells' order, instead
// of through its own translucency passes; the renderer must not use depth peeling.
// Props drawn after it (in the same pass) still depth-test against whatever wrote depth
// before; this mapper writes no depth.
class OrderedPolyDataMapper : public vtkOpenGLPolyDataMapper {
 public:
  static OrderedPolyDataMapper* New();
  vtkTypeMacro(OrderedPolyDataMapper, vtkOpenGLPolyDataMapper);

  void RenderPieceStart(vtkRenderer* ren, vtkActor* act) override;
  void RenderPieceFinish(vtkRenderer* ren, vtkActor* act) override;

  OrderedPolyDataMapper(const OrderedPolyDataMapper&) = delete;
  OrderedPolyDataMapper& operator=(const OrderedPolyDataMapper&) = delete;

 protected:
  OrderedPolyDataMapper() = default;
  ~OrderedPolyDataMapper() override = default;

 private:
  bool saved_depth_test_ = true;
  bool saved_blend_ = false;
  std::array<int, 4> saved_blend_func_{};
};

}  // namespace terravol::app
