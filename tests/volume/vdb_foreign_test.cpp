// .vdb files written by other tools: sparse grids, other value types, other transforms.
#include <gtest/gtest.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <sstream>

#include "io/error.h"
#include "volume/readers.h"

namespace terravol::volume {
namespace {

std::string bytes_of(const openvdb::GridPtrVec& grids) {
  std::ostringstream out(std::ios::binary);
  openvdb::io::Stream(out).write(grids);
  return out.str();
}

std::string error_of(const std::string& bytes, const ReadOptions& o = {}) {
  try {
    parse_vdb(bytes, "f.vdb", o);
  } catch (const io::FormatError& e) {
    return e.what();
  }
  return "no error";
}

class VdbForeign : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { openvdb::initialize(); }
};

TEST_F(VdbForeign, SparseGridBecomesItsActiveBoxWithTheBackgroundElsewhere) {
  auto grid = openvdb::FloatGrid::create(-1.5f);
  grid->setName("sparse");
  grid->setTransform(openvdb::math::Transform::createLinearTransform(2.0));
  auto acc = grid->getAccessor();
  acc.setValueOn(openvdb::Coord(10, 20, 30), 5.0f);
  acc.setValueOn(openvdb::Coord(12, 21, 30), 7.0f);
  const Volume v = parse_vdb(bytes_of({grid}), "f.vdb");
  EXPECT_EQ(v.lattice.dims, (std::array<int, 3>{3, 2, 1}));
  EXPECT_EQ(v.lattice.origin, (std::array<double, 3>{20.0, 40.0, 60.0}));
  EXPECT_EQ(v.lattice.spacing, (std::array<double, 3>{2.0, 2.0, 2.0}));
  EXPECT_EQ(v.values, (std::vector<float>{5.0f, -1.5f, -1.5f, -1.5f, -1.5f, 7.0f}));
  EXPECT_EQ(v.background, -1.5f);
  EXPECT_EQ(v.active_points, 2u);
  EXPECT_EQ(v.frame.kind, FrameKind::kNone);
}

TEST_F(VdbForeign, SkipsNonFloatGridsByDefaultAndRefusesThemByName) {
  auto vec = openvdb::Vec3SGrid::create();
  vec->setName("wind");
  vec->tree().setValueOn(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1, 2, 3));
  auto f = openvdb::FloatGrid::create();
  f->setName("density");
  f->tree().setValueOn(openvdb::Coord(1, 1, 1), 2.0f);
  const std::string bytes = bytes_of({vec, f});
  EXPECT_EQ(parse_vdb(bytes, "f.vdb").name, "density");
  ReadOptions o;
  o.field = "wind";
  EXPECT_EQ(error_of(bytes, o), "f.vdb: grid 'wind' holds vec3s, not float");
  EXPECT_EQ(error_of(bytes_of({vec})), "f.vdb: no float grid (grids: 'wind' (vec3s))");
}

TEST_F(VdbForeign, RefusesRotatedFrustumAndEmptyGrids) {
  auto rotated = openvdb::FloatGrid::create();
  rotated->setName("r");
  rotated->tree().setValueOn(openvdb::Coord(0, 0, 0), 1.0f);
  openvdb::math::Transform::Ptr t = openvdb::math::Transform::createLinearTransform(1.0);
  t->postRotate(0.3, openvdb::math::Z_AXIS);
  rotated->setTransform(t);
  EXPECT_EQ(error_of(bytes_of({rotated})), "f.vdb: grid 'r': rotated or sheared transform is not supported (axis-aligned only)");

  auto frustum = openvdb::FloatGrid::create();
  frustum->setName("f");
  frustum->tree().setValueOn(openvdb::Coord(0, 0, 0), 1.0f);
  frustum->setTransform(openvdb::math::Transform::createFrustumTransform(
      openvdb::BBoxd(openvdb::Vec3d(0, 0, 0), openvdb::Vec3d(10, 10, 10)), 0.5, 10.0, 1.0));
  EXPECT_EQ(error_of(bytes_of({frustum})), "f.vdb: grid 'f': non-linear (frustum) transform is not supported");

  auto empty = openvdb::FloatGrid::create();
  empty->setName("e");
  EXPECT_EQ(error_of(bytes_of({empty})), "f.vdb: grid 'e': no active voxels");
}

TEST_F(VdbForeign, RefusesSparseGridsTooLargeToMakeDense) {
  auto grid = openvdb::FloatGrid::create();
  grid->setName("far");
  grid->tree().setValueOn(openvdb::Coord(0, 0, 0), 1.0f);
  grid->tree().setValueOn(openvdb::Coord(100000, 100000, 100000), 1.0f);
  EXPECT_EQ(error_of(bytes_of({grid})), "f.vdb: dimensions 100001 x 100001 x 100001 are too large (at most 2^28 points)");
}

TEST_F(VdbForeign, NegativeScaleIsUndoneByReversingTheAxis) {
  auto grid = openvdb::FloatGrid::create();
  grid->setName("flip");
  grid->setTransform(openvdb::math::Transform::Ptr(new openvdb::math::Transform(openvdb::math::MapBase::Ptr(
      new openvdb::math::ScaleTranslateMap(openvdb::Vec3d(1, -2, 1), openvdb::Vec3d(0, 100, 0))))));
  grid->tree().setValueOn(openvdb::Coord(0, 0, 0), 1.0f);  // y = 100
  grid->tree().setValueOn(openvdb::Coord(0, 1, 0), 2.0f);  // y = 98
  const Volume v = parse_vdb(bytes_of({grid}), "f.vdb");
  EXPECT_EQ(v.lattice.origin[1], 98.0);
  EXPECT_EQ(v.lattice.spacing[1], 2.0);
  EXPECT_EQ(v.values, (std::vector<float>{2.0f, 1.0f}));
}

}  // namespace
}  // namespace terravol::volume
