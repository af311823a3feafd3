#include "app/render/ordered_mapper.h"

#include <vtkActor.h>
#include <vtkCellArray.h>
#include <vtkDataSetAttributes.h>
#include <vtkObjectFactory.h>
#include <vtkOpenGLIndexBufferObject.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLState.h>
#include <vtkPointData.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkTypeInt32Array.h>
#include <vtk_glew.h>

namespace terravol::app::render {

vtkStandardNewMacro(OrderedPolyDataMapper);

namespace {

vtkOpenGLState* state_of(vtkRenderer* ren) {
  return static_cast<vtkOpenGLRenderWindow*>(ren->GetRenderWindow())->GetState();
}

}  // namespace

void OrderedPolyDataMapper::RenderPieceStart(vtkRenderer* ren, vtkActor* act) {
  vtkOpenGLPolyDataMapper::RenderPieceStart(ren, act);
  vtkOpenGLState* state = state_of(ren);
  saved_depth_test_ = state->GetEnumState(GL_DEPTH_TEST);
  saved_blend_ = state->GetEnumState(GL_BLEND);
  state->GetBlendFuncState(saved_blend_func_.data());
  state->vtkglDisable(GL_DEPTH_TEST);
  if (blending_) {
    state->vtkglEnable(GL_BLEND);
  } else {
    state->vtkglDisable(GL_BLEND);
  }
  state->vtkglBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE,
                                GL_ONE_MINUS_SRC_ALPHA);
}

void OrderedPolyDataMapper::BuildIBO(vtkRenderer* ren, vtkActor* act, vtkPolyData* poly) {
  vtkProperty* property = act->GetProperty();
  vtkCellArray* polys = poly->GetPolys();
  const bool direct =
      property->GetRepresentation() == VTK_SURFACE && !property->GetEdgeVisibility() &&
      !property->GetVertexVisibility() && ren->GetSelector() == nullptr &&
      poly->GetPointData()->GetAttribute(vtkDataSetAttributes::EDGEFLAG) == nullptr &&
      poly->GetVerts()->GetNumberOfCells() == 0 && poly->GetLines()->GetNumberOfCells() == 0 &&
      poly->GetStrips()->GetNumberOfCells() == 0 && !polys->IsStorage64Bit() &&
      polys->IsHomogeneous() == 3;
  if (!direct) {
    Superclass::BuildIBO(ren, act, poly);
    return;
  }
  // VTK's buffers for the other primitives (all empty here), then the triangles'.
  no_triangles_->SetPoints(poly->GetPoints());
  Superclass::BuildIBO(ren, act, no_triangles_);
  vtkTypeInt32Array* ids = polys->GetConnectivityArray32();
  const auto count = static_cast<std::size_t>(ids->GetNumberOfValues());
  static_assert(sizeof(vtkTypeInt32) == sizeof(unsigned int),
                "32-bit ids upload as GL_UNSIGNED_INT");
  vtkOpenGLIndexBufferObject* ibo = this->Primitives[PrimitiveTris].IBO;
  ibo->Upload(reinterpret_cast<const unsigned int*>(ids->GetPointer(0)), count,
              vtkOpenGLBufferObject::ElementArrayBuffer);
  ibo->IndexCount = count;
}

void OrderedPolyDataMapper::RenderPieceFinish(vtkRenderer* ren, vtkActor* act) {
  vtkOpenGLState* state = state_of(ren);
  state->SetEnumState(GL_DEPTH_TEST, saved_depth_test_);
  state->SetEnumState(GL_BLEND, saved_blend_);
  state->vtkglBlendFuncSeparate(
      static_cast<unsigned>(saved_blend_func_[0]), static_cast<unsigned>(saved_blend_func_[1]),
      static_cast<unsigned>(saved_blend_func_[2]), static_cast<unsigned>(saved_blend_func_[3]));
  vtkOpenGLPolyDataMapper::RenderPieceFinish(ren, act);
}

}  // namespace terravol::app::render
