#include "app/ordered_mapper.h"

#include <vtkObjectFactory.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLState.h>
#include <vtkRenderer.h>
#include <vtk_glew.h>

namespace terravol::app {

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
  state->vtkglEnable(GL_BLEND);
  state->vtkglBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
}

void OrderedPolyDataMapper::RenderPieceFinish(vtkRenderer* ren, vtkActor* act) {
  vtkOpenGLState* state = state_of(ren);
  state->SetEnumState(GL_DEPTH_TEST, saved_depth_test_);
  state->SetEnumState(GL_BLEND, saved_blend_);
  state->vtkglBlendFuncSeparate(static_cast<unsigned>(saved_blend_func_[0]), static_cast<unsigned>(saved_blend_func_[1]),
                                static_cast<unsigned>(saved_blend_func_[2]), static_cast<unsigned>(saved_blend_func_[3]));
  vtkOpenGLPolyDataMapper::RenderPieceFinish(ren, act);
}

}  // namespace terravol::app
