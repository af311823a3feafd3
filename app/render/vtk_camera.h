// The tree's camera (app/scene/camera.h, mrbsp::Camera) as a vtkCamera.
#pragma once

#include "mrbsp/terrain_tree.h"

class vtkCamera;

namespace terravol::app::render {

// Gives a vtkCamera the same view: position, focal point one metre ahead, view up, vertical view
// angle, and the clipping range [camera.near_plane, far_plane].
void apply_camera(const mrbsp::Camera& camera, double far_plane, vtkCamera& vtk_camera);

}  // namespace terravol::app::render
