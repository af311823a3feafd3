// app/render/vtk_camera.h: the tree's camera as a vtkCamera.
#include <gtest/gtest.h>

#include <vtkCamera.h>
#include <vtkNew.h>

#include "app/render/vtk_camera.h"
#include "app/scene/camera.h"
#include "io/scene_frame.h"

namespace terravol::app::render {
namespace {

TEST(SceneCamera, VtkCameraGetsTheSameView) {
  const io::SceneFrame frame(45.0, 6.0);
  const auto c = scene::make_scene_camera(frame, {45.1, 6.1, 0, 30, -10}, 2000.0, 40.0, 800, 600, 5.0);
  vtkNew<vtkCamera> vc;
  apply_camera(c, 50000.0, *vc);
  const double* pos = vc->GetPosition();
  const double* dir = vc->GetDirectionOfProjection();
  EXPECT_NEAR(pos[2], c.eye.z, 1e-9);
  EXPECT_NEAR(dir[0], c.forward.x, 1e-9);
  EXPECT_NEAR(dir[2], c.forward.z, 1e-9);
  EXPECT_DOUBLE_EQ(vc->GetViewAngle(), 40.0);
  EXPECT_DOUBLE_EQ(vc->GetClippingRange()[0], 5.0);
  EXPECT_DOUBLE_EQ(vc->GetClippingRange()[1], 50000.0);
}

}  // namespace
}  // namespace terravol::app::render
