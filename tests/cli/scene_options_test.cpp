// The scene options of render, view and fly (app/cli/scene_options.h).
#include "app/cli/scene_options.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "volume/geometry.h"

namespace terravol::app::cli {
namespace {

TEST(ReadSceneArgs, IsosurfacesOfEachVolumeTakeTheirOwnPaletteColoursUnlessGivenOne) {
  SceneArgs args;
  args.volumes = {"a.vdb", "b.vdb"};
  args.isos = {"110", "125,color=1:2:3"};
  std::vector<std::filesystem::path> dems{std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"};
  const scene::SceneSpec scene = read_scene_args(args, dems);
  ASSERT_EQ(scene.volumes.size(), 2u);
  for (const scene::VolumeSpec& v : scene.volumes) {
    ASSERT_EQ(v.isosurfaces.size(), 2u);
    EXPECT_EQ(v.isosurfaces[1].color, glm::u8vec3(1, 2, 3));  // given: the same in both
  }
  EXPECT_EQ(scene.volumes[0].isosurfaces[0].color, volume::default_isosurface_color(0));
  EXPECT_EQ(scene.volumes[1].isosurfaces[0].color, volume::default_isosurface_color(2));
  EXPECT_NE(scene.volumes[0].isosurfaces[0].color, scene.volumes[1].isosurfaces[0].color);
}

}  // namespace
}  // namespace terravol::app::cli
