// app/render/scene_renderer.h: the scene pipeline's slides, synchronous (render, fly) and read
// ahead on a worker thread (view), over the bundled DEM.
#include <gtest/gtest.h>

#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "app/render/scene_renderer.h"
#include "app/scene/camera.h"
#include "app/scene/scene_file.h"
#include "io/grid.h"
#include "io/mosaic.h"
#include "io/void_fill.h"
#include "require_display.h"
#include "run_command.h"
#include "temp_dir.h"
#include "volume/geometry.h"

namespace terravol::app::render {
namespace {

std::string bundled_dem() { return std::string(TERRAVOL_SOURCE_DIR) + "/data/dem/N45E006.hgt"; }

// The first window is centred on (45.5 N, 6.5 E), lattice row and column 600 of the tile; the
// frames look from 100 samples farther north, within a quarter of the 256-cell window of its
// north edge, so the first of them slides the window north.
constexpr double kStartLat = 45.5, kLon = 6.5;
constexpr double kNorthLat = 46.0 - 500.0 / 1200.0;

scene::SceneSpec scene_spec(const std::vector<scene::VolumeSpec>& volumes = {}) {
  scene::SceneSpec spec;
  spec.dems = {bundled_dem()};
  spec.volumes = volumes;
  spec.camera = scene::SceneCamera{scene::CameraPose{kStartLat, kLon, 1500.0, 0.0, -20.0}, true, 45.0};
  return spec;
}

RenderSettings small_settings() {
  RenderSettings s;
  s.width = 160;
  s.height = 90;
  return s;
}

SceneOptions options(Sliding sliding) {
  SceneOptions o;
  o.max_window = 256;
  o.sliding = sliding;
  o.surface_triangles = 2000;
  return o;
}

const scene::CameraPose kNorth{kNorthLat, kLon, 1500.0, 0.0, -20.0};

// Renders the northern view until the window has slid once; false after 60 s.
bool render_until_slid(SceneRenderer& r) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < end) {
    if (r.render(kNorth, true, 45.0, {}).slides == 1) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

// The heights of the window, row 0 south, as the mosaic itself gives them (voids filled).
std::vector<float> mosaic_heights(const scene::WindowChoice& w) {
  const io::Mosaic mosaic = io::Mosaic::open({bundled_dem()});
  io::Grid g = mosaic.read_window(w.row0, w.col0, w.cells + 1, w.cells + 1);
  io::fill_voids(g);
  std::vector<float> h;
  for (int j = 0; j <= w.cells; ++j)
    for (int i = 0; i <= w.cells; ++i) h.push_back(g.heights[g.index(w.cells - j, i)]);
  return h;
}

void expect_same_slide(SceneRenderer& sync, SceneRenderer& async) {
  const scene::WindowChoice& a = sync.terrain().window();
  const scene::WindowChoice& b = async.terrain().window();
  EXPECT_EQ(a.row0, b.row0);
  EXPECT_EQ(a.col0, b.col0);
  EXPECT_LT(a.row0, 600 - 128) << "the window moved north";
  EXPECT_EQ((600 - 128 - a.row0) % 32, 0) << "by whole cells of the coarsest level (6 levels: 32 samples)";
  const std::vector<float> expected = mosaic_heights(a);
  const auto heights = async.terrain().heights();
  ASSERT_EQ(heights.size(), expected.size());
  EXPECT_TRUE(std::equal(heights.begin(), heights.end(), expected.begin())) << "the moved window's samples";
  EXPECT_EQ(sync.terrain().tree().positions(), async.terrain().tree().positions());
  EXPECT_EQ(sync.last_frame().indices, async.last_frame().indices);
  EXPECT_EQ(sync.rgb(), async.rgb()) << "the same picture after either slide";
}

TEST(SceneRenderer, TheSynchronousSlideHappensWithinTheFrame) {
  TERRAVOL_REQUIRE_DISPLAY();
  SceneRenderer r(scene_spec(), small_settings(), options(Sliding::kSynchronous));
  EXPECT_EQ(r.render(scene_spec().camera->pose, true, 45.0, {}).slides, 0) << "centred: no slide";
  const FrameStats f = r.render(kNorth, true, 45.0, {});
  EXPECT_EQ(f.slides, 1);
  EXPECT_GT(f.slide_ms, 0.0);
  EXPECT_FALSE(r.slide_pending());
}

TEST(SceneRenderer, AReadAheadSlideLandsAtALaterFrameAsTheSynchronousOneDoes) {
  TERRAVOL_REQUIRE_DISPLAY();
  SceneRenderer sync(scene_spec(), small_settings(), options(Sliding::kSynchronous));
  SceneRenderer async(scene_spec(), small_settings(), options(Sliding::kAsynchronous));
  ASSERT_EQ(sync.render(kNorth, true, 45.0, {}).slides, 1);
  const FrameStats first = async.render(kNorth, true, 45.0, {});
  EXPECT_EQ(first.slides, 0) << "the moved window is read on the worker thread, not in this frame";
  EXPECT_TRUE(async.slide_pending());
  ASSERT_TRUE(render_until_slid(async));
  EXPECT_FALSE(async.slide_pending());
  EXPECT_GT(async.last_slide().read_ms, 0.0);
  EXPECT_GT(async.last_slide().worker_tree_ms, 0.0) << "the tree slid on the worker, on a copy of the scene";
  EXPECT_EQ(sync.last_slide().worker_tree_ms, 0.0) << "the synchronous slide is made on the calling thread";
  EXPECT_TRUE(async.memory_to_return()) << "the old scene's pages wait for the viewer to rest";
  EXPECT_FALSE(sync.memory_to_return()) << "the synchronous slide gives them back itself";
  async.return_memory();
  EXPECT_FALSE(async.memory_to_return());
  sync.render(kNorth, true, 45.0, {});
  expect_same_slide(sync, async);
}

// A 3 km RF volume over the bundled tile that the slide north keeps in the window (written into
// `dir`), with an isosurface at 110 dB and a slice 300 m above the ground.
scene::VolumeSpec volume_near_the_slide(const test::TempDir& dir) {
  const auto vdb = dir.path() / "rf.vdb";
  const auto r = test::run_terravol("rf --quiet --tx 45.55,6.5,30 --dem " + bundled_dem() +
                                    " --radius-km 3 --heights 0:600:100 -o " + vdb.string());
  EXPECT_EQ(r.status, 0) << r.err;
  scene::VolumeSpec v;
  v.file = vdb;
  v.isosurfaces = {volume::parse_isosurface("110")};
  v.slices = {volume::parse_slice("agl=300")};
  return v;
}

TEST(SceneRenderer, BothSlidesMergeTheVolumesAgainIntoTheMovedWindow) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const scene::VolumeSpec v = volume_near_the_slide(dir);
  SceneRenderer sync(scene_spec({v}), small_settings(), options(Sliding::kSynchronous));
  SceneRenderer async(scene_spec({v}), small_settings(), options(Sliding::kAsynchronous));
  const std::size_t merged = sync.merge_figures().tree_triangles;
  EXPECT_GT(merged, 0u);
  ASSERT_EQ(sync.render(kNorth, true, 45.0, {}).slides, 1);
  async.render(kNorth, true, 45.0, {});
  ASSERT_TRUE(render_until_slid(async));
  sync.render(kNorth, true, 45.0, {});
  EXPECT_GT(sync.last_frame().indices.size(), 0u);
  EXPECT_EQ(sync.terrain().tree().merged_colors(), async.terrain().tree().merged_colors());
  expect_same_slide(sync, async);
}

// The worker slides a copy of the scene; an edit that comes after the copy was taken is not in
// it, so that copy is not swapped in: the edited scene itself slides when the frame lands.
TEST(SceneRenderer, AnEditDuringTheReadAheadIsInTheSlidTree) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const scene::VolumeSpec v = volume_near_the_slide(dir);
  const volume::SliceSpec moved = volume::parse_slice("agl=250");
  SceneRenderer sync(scene_spec({v}), small_settings(), options(Sliding::kSynchronous));
  SceneRenderer async(scene_spec({v}), small_settings(), options(Sliding::kAsynchronous));
  sync.volumes().set_slice(0, 0, moved);
  sync.remerge();
  ASSERT_EQ(sync.render(kNorth, true, 45.0, {}).slides, 1);
  async.render(kNorth, true, 45.0, {});
  ASSERT_TRUE(async.slide_pending());
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!async.slide_ready() && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(async.slide_ready()) << "the copy was slid on the worker";
  async.volumes().set_slice(0, 0, moved);
  async.remerge();
  ASSERT_TRUE(render_until_slid(async));
  EXPECT_EQ(async.last_slide().worker_tree_ms, 0.0) << "the copy predates the edit: the scene slid on this thread";
  sync.render(kNorth, true, 45.0, {});
  EXPECT_EQ(sync.terrain().tree().merged_colors(), async.terrain().tree().merged_colors());
  expect_same_slide(sync, async);
}

// Share of pixels of two RGB images (same size) differing by more than `tolerance` in a channel.
double share_differing(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b, int tolerance) {
  if (a.size() != b.size() || a.empty()) return 1.0;
  std::size_t differ = 0;
  for (std::size_t p = 0; p + 2 < a.size(); p += 3) {
    bool d = false;
    for (int k = 0; k < 3; ++k) d = d || std::abs(int(a[p + k]) - int(b[p + k])) > tolerance;
    differ += d;
  }
  return static_cast<double>(differ) / static_cast<double>(a.size() / 3);
}

// Edits re-merge one surface and upload only the vertices the tree appended (sync_vertices);
// the picture after them is the one a pipeline built from the edited scene draws, including
// the low alternatives built lazily by the traversals in between.
TEST(SceneRenderer, EditedVolumesDrawWhatAPipelineBuiltFromTheEditedSceneDraws) {
  TERRAVOL_REQUIRE_DISPLAY();
  test::TempDir dir;
  const auto vdb = dir.path() / "rf.vdb";
  const auto r = test::run_terravol("rf --quiet --tx 45.52,6.5,30 --dem " + bundled_dem() +
                                    " --radius-km 3 --heights 0:600:100 -o " + vdb.string());
  ASSERT_EQ(r.status, 0) << r.err;
  scene::VolumeSpec v;
  v.file = vdb;
  v.isosurfaces = {volume::parse_isosurface("105,opacity=0.5"), volume::parse_isosurface("115,opacity=0.4")};
  v.slices = {volume::parse_slice("agl=200,opacity=0.5")};
  const scene::CameraPose near{45.49, 6.49, 400.0, 20.0, -10.0};
  const scene::CameraPose far{45.46, 6.46, 1500.0, 30.0, -20.0};
  SceneRenderer edited(scene_spec({v}), small_settings(), options(Sliding::kSynchronous));
  edited.render(far, true, 45.0, {});
  edited.render(near, true, 45.0, {});  // builds low alternatives on the way
  scene::VolumeSpec after = v;
  after.isosurfaces[0] = volume::parse_isosurface("108,opacity=0.5");
  after.slices[0] = volume::parse_slice("agl=350,opacity=0.5");
  edited.volumes().set_isosurface(0, 0, after.isosurfaces[0]);
  edited.volumes().set_slice(0, 0, after.slices[0]);
  EXPECT_EQ(edited.remerge().merged_surfaces, 2u) << "only the two edited surfaces";
  SceneRenderer fresh(scene_spec({after}), small_settings(), options(Sliding::kSynchronous));
  for (const scene::CameraPose& pose : {near, far}) {
    edited.render(pose, true, 45.0, {});
    fresh.render(pose, true, 45.0, {});
    EXPECT_GT(edited.last_frame().indices.size(), 0u);
    // The edited slots' BSPs split differently from fresh ones (insertion against a fresh
    // autopartition), so pieces differ where they meet; the composite may differ by rounding (here 1-3 of 14,400 pixels).
    EXPECT_LT(share_differing(edited.rgb(), fresh.rgb(), 3), 0.002) << "pose at " << pose.alt << " m";
  }
  // A second edit: its vertices go into the room the first one reserved after the renderer's
  // vertices, written in place (TerrainRenderer::append_merged_vertices).
  scene::VolumeSpec again = after;
  again.isosurfaces[0] = volume::parse_isosurface("111,opacity=0.5");
  again.slices[0] = volume::parse_slice("agl=280,opacity=0.5");
  edited.volumes().set_isosurface(0, 0, again.isosurfaces[0]);
  edited.volumes().set_slice(0, 0, again.slices[0]);
  edited.remerge();
  SceneRenderer fresh_again(scene_spec({again}), small_settings(), options(Sliding::kSynchronous));
  for (const scene::CameraPose& pose : {near, far}) {
    edited.render(pose, true, 45.0, {});
    fresh_again.render(pose, true, 45.0, {});
    EXPECT_LT(share_differing(edited.rgb(), fresh_again.rgb(), 3), 0.002) << "second edit, pose at " << pose.alt << " m";
  }
  // Edits until the tree compacts its merged vertices (renumbering them over the same terrain):
  // the renderer then takes the merged vertices alone, in place
  // (TerrainRenderer::replace_merged_vertices).
  const std::uint64_t version = edited.terrain().tree().merged_version();
  for (int k = 0; k < 12 && edited.terrain().tree().merged_version() == version; ++k) {
    again.slices[0] = volume::parse_slice(k % 2 ? "agl=280,opacity=0.5" : "agl=330,opacity=0.5");
    edited.volumes().set_slice(0, 0, again.slices[0]);
    edited.remerge();
    edited.render(k % 2 ? near : far, true, 45.0, {});
  }
  ASSERT_NE(edited.terrain().tree().merged_version(), version) << "no compaction after 12 edits";
  SceneRenderer fresh_compacted(scene_spec({again}), small_settings(), options(Sliding::kSynchronous));
  for (const scene::CameraPose& pose : {near, far}) {
    edited.render(pose, true, 45.0, {});
    fresh_compacted.render(pose, true, 45.0, {});
    EXPECT_LT(share_differing(edited.rgb(), fresh_compacted.rgb(), 3), 0.002) << "compacted, pose at " << pose.alt << " m";
  }
  // Hiding the volume removes its surfaces alone; showing it again brings them back.
  edited.volumes().set_visible(0, false);
  EXPECT_EQ(edited.remerge().merged_surfaces, 4u) << "two isosurfaces, the slice and the transmitter marker";
  EXPECT_EQ(edited.terrain().tree().merge_stats().stored_polygons, 0u);
  edited.volumes().set_visible(0, true);
  edited.remerge();
  edited.render(far, true, 45.0, {});
  fresh_compacted.render(far, true, 45.0, {});
  EXPECT_LT(share_differing(edited.rgb(), fresh_compacted.rgb(), 3), 0.002);
}

}  // namespace
}  // namespace terravol::app::render
