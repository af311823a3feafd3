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
#include <vtkOpenGLShaderCache.h>
#include <vtkOpenGLState.h>
#include <vtkOpenGLVertexArrayObject.h>
#include <vtkPointData.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkShader.h>
#include <vtkShaderProgram.h>
#include <vtkTypeInt32Array.h>
#include <vtk_glew.h>

#include <string>

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
  direct_ = direct;
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
  // VTK keeps the copy of each vertex array it packed for an upload (PackedVBO), beside the
  // array and the GL buffer (host memory under llvmpipe); it packs again from the arrays for
  // every upload, so the copy is freed here. That is about 400 MB less held through a session
  // with a 4096-cell window, but not a lower peak: every copy exists at the end of the upload.
  for (const char* name : {"vertexMC", "tcoord", "scalarColor"}) {
    if (vtkOpenGLVertexBufferObject* vbo = this->VBOs->GetVBO(name)) std::vector<float>().swap(vbo->GetPackedVBO());
  }
  if (update_count_ == 0) return;
  const std::size_t first = update_first_, count = update_count_;
  update_count_ = 0;
  vtkPolyData* poly = this->CurrentInput;
  if (poly == nullptr || poly->GetPoints() == nullptr) return;
  // Positions: as VTK packs them (3 floats a vertex, shifted and scaled when it does so).
  vtkOpenGLVertexBufferObject* vbo = this->VBOs->GetVBO("vertexMC");
  if (vbo != nullptr) {
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

bool OrderedPolyDataMapper::ready_plain(vtkRenderer* ren, vtkActor* act) {
  vtkOpenGLHelper& tris = this->Primitives[PrimitiveTris];
  vtkOpenGLShaderCache* cache = static_cast<vtkOpenGLRenderWindow*>(ren->GetRenderWindow())->GetShaderCache();
  if (plain_.Program == nullptr || plain_source_ != tris.Program || tris.ShaderSourceTime > plain_.ShaderSourceTime) {
    plain_.Program = nullptr;
    plain_source_ = nullptr;
    std::string fs = tris.Program->GetFragmentShader()->GetSource();
    const std::size_t begin = fs.find(kTextureBegin);
    const std::size_t end = fs.find(kTextureEnd);
    if (begin == std::string::npos || end == std::string::npos || end < begin) return false;
    fs.replace(begin, end + kTextureEnd.size() - begin, "gl_FragData[0] = vertexColorVSOutput;");
    // VTK's sources as it compiled them: its replacements are done, so the cache's own pass
    // changes nothing but the output's name in the line above.
    vtkShaderProgram* plain = cache->ReadyShaderProgram(tris.Program->GetVertexShader()->GetSource().c_str(), fs.c_str(),
                                                        tris.Program->GetGeometryShader()->GetSource().c_str());
    if (plain == nullptr) return false;
    plain_.Program = plain;
    plain_source_ = tris.Program;
    plain_.ShaderSourceTime.Modified();
    plain_.VAO->ReleaseGraphicsResources();
  } else if (cache->ReadyShaderProgram(plain_.Program) == nullptr) {
    return false;
  }
  plain_.VAO->Bind();
  if (this->VBOs->GetMTime() > plain_.AttributeUpdateTime || plain_.ShaderSourceTime > plain_.AttributeUpdateTime) {
    this->VBOs->AddAllAttributesToVAO(plain_.Program, plain_.VAO);
    plain_.AttributeUpdateTime.Modified();
  }
  // The uniforms VTK's program gets for an unlit, untextured surface (UpdateShaders).
  this->SetCustomUniforms(plain_, act);
  this->SetPropertyShaderParameters(plain_, ren, act);
  this->SetCameraShaderParameters(plain_, ren, act);
  return true;
}

void OrderedPolyDataMapper::RenderPieceDraw(vtkRenderer* ren, vtkActor* act) {
  vtkOpenGLHelper& tris = this->Primitives[PrimitiveTris];
  const std::size_t triangles = tris.IBO->IndexCount / 3;
  const bool split = direct_ && !untextured_.empty() && ren->GetSelector() == nullptr &&
                     untextured_.back().first + untextured_.back().count <= triangles;
  if (!split) {
    Superclass::RenderPieceDraw(ren, act);
    return;
  }
  // VTK's program, bound with its uniforms and VAO; then the untextured one, if the shader has
  // the block to replace.
  this->UpdateShaders(tris, ren, act);
  vtkOpenGLShaderCache* cache = static_cast<vtkOpenGLRenderWindow*>(ren->GetRenderWindow())->GetShaderCache();
  if (!ready_plain(ren, act)) {
    cache->ReadyShaderProgram(tris.Program);
    tris.VAO->Bind();
    Superclass::RenderPieceDraw(ren, act);
    return;
  }
  const auto last = static_cast<GLuint>(this->VBOs->GetNumberOfTuples("vertexMC") - 1);
  auto draw = [&](vtkOpenGLHelper& with, std::size_t first, std::size_t count) {
    if (count == 0) return;
    cache->ReadyShaderProgram(with.Program);
    with.VAO->Bind();
    tris.IBO->Bind();
    glDrawRangeElements(GL_TRIANGLES, 0, last, static_cast<GLsizei>(3 * count), GL_UNSIGNED_INT,
                        reinterpret_cast<const GLvoid*>(3 * first * sizeof(GLuint)));
  };
  std::size_t next = 0;
  for (const Run& run : untextured_) {
    draw(tris, next, run.first - next);
    draw(plain_, run.first, run.count);
    next = run.first + run.count;
  }
  draw(tris, next, triangles - next);
  // As VTK leaves it: its program and VAO bound (RenderPieceFinish releases that VAO).
  tris.IBO->Release();
  cache->ReadyShaderProgram(tris.Program);
  tris.VAO->Bind();
}

void OrderedPolyDataMapper::ReleaseGraphicsResources(vtkWindow* win) {
  plain_.ReleaseGraphicsResources(win);
  plain_.Program = nullptr;
  plain_source_ = nullptr;
  Superclass::ReleaseGraphicsResources(win);
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
