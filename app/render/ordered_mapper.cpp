#include "app/render/ordered_mapper.h"

#include <vtkActor.h>
#include <vtkCellArray.h>
#include <vtkDataSetAttributes.h>
#include <vtkObjectFactory.h>
#include <vtkOpenGLIndexBufferObject.h>
#include <vtkOpenGLVertexBufferObject.h>
#include <vtkOpenGLVertexBufferObjectGroup.h>
#include <vtkPoints.h>
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

void OrderedPolyDataMapper::BuildBufferObjects(vtkRenderer* ren, vtkActor* act) {
  Superclass::BuildBufferObjects(ren, act);
  if (update_count_ == 0) return;
  const std::size_t first = update_first_, count = update_count_;
  update_count_ = 0;
  vtkPolyData* poly = this->CurrentInput;
  if (poly == nullptr || poly->GetPoints() == nullptr) return;
  // Positions: as VTK packs them (3 floats a vertex, shifted and scaled when it does so).
  if (vtkOpenGLVertexBufferObject* vbo = this->VBOs->GetVBO("vertexMC")) {
    auto* points = static_cast<const float*>(poly->GetPoints()->GetData()->GetVoidPointer(0));
    const unsigned stride = vbo->GetStride();
    const bool shifted = vbo->GetCoordShiftAndScaleEnabled();
    const float* data = points + 3 * first;
    if (shifted || stride != 3 * sizeof(float)) {
      const std::size_t per = stride / sizeof(float);
      packed_.assign(per * count, 0.0f);
      const std::vector<double>& shift = vbo->GetShift();
      const std::vector<double>& scale = vbo->GetScale();
      for (std::size_t v = 0; v < count; ++v)
        for (std::size_t a = 0; a < 3; ++a) {
          const double p = points[3 * (first + v) + a];
          packed_[per * v + a] = static_cast<float>(shifted ? (p - shift[a]) * scale[a] : p);
        }
      data = packed_.data();
    }
    vbo->Bind();
    glBufferSubData(GL_ARRAY_BUFFER, static_cast<GLintptr>(first * stride), static_cast<GLsizeiptr>(count * stride), data);
    vbo->Release();
  }
  // Colours: RGBA bytes (absent when the colours are per cell, --lod-colors).
  vtkDataArray* scalars = poly->GetPointData()->GetScalars();
  vtkOpenGLVertexBufferObject* colours = this->VBOs->GetVBO("scalarColor");
  if (colours != nullptr && scalars != nullptr && colours->GetStride() == 4) {
    colours->Bind();
    glBufferSubData(GL_ARRAY_BUFFER, static_cast<GLintptr>(first * 4), static_cast<GLsizeiptr>(count * 4),
                    static_cast<const unsigned char*>(scalars->GetVoidPointer(0)) + 4 * first);
    colours->Release();
  }
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
