#include "app/render/vtk_camera.h"

#include <vtkCamera.h>

#include <glm/vec3.hpp>

namespace terravol::app::render {

void apply_camera(const mrbsp::Camera& camera, double far_plane, vtkCamera& vtk_camera) {
  const glm::dvec3 focal = camera.eye + camera.forward;
  vtk_camera.SetPosition(camera.eye.x, camera.eye.y, camera.eye.z);
  vtk_camera.SetFocalPoint(focal.x, focal.y, focal.z);
  vtk_camera.SetViewUp(camera.up.x, camera.up.y, camera.up.z);
  vtk_camera.SetViewAngle(camera.fov_y_deg);
  vtk_camera.UseHorizontalViewAngleOff();
  vtk_camera.SetClippingRange(camera.near_plane, far_plane);
}

}  // namespace terravol::app::render
