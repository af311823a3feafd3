// The volume readers: round trips through .vdb, .vti and legacy .vtk, the real hydrogen.vtk,
// and hostile input (truncations at many lengths, garbage, absurd headers).
#include "volume/readers.h"

#include <gtest/gtest.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkShortArray.h>
#include <vtkStringArray.h>
#include <vtkStructuredPoints.h>
#include <vtkStructuredPointsWriter.h>
#include <vtkXMLImageDataWriter.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <random>

#include "io/error.h"
#include "shared_data.h"
#include "temp_dir.h"
#include "volume/vdb_write.h"
#include "volume_test_util.h"

namespace terravol::volume {
namespace {

using test::expect_volume_or_one_line_error;
using test::random_volume;

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void expect_same(const Volume& a, const Volume& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.units, b.units);
  EXPECT_EQ(a.frame, b.frame);
  EXPECT_EQ(a.lattice, b.lattice);
  EXPECT_EQ(a.attributes, b.attributes);
  ASSERT_EQ(a.values.size(), b.values.size());
  EXPECT_TRUE(std::equal(a.values.begin(), a.values.end(), b.values.begin()));
}

// ---- .vdb ----

TEST(VdbRoundTrip, ReadsBackExactlyInEveryFrame) {
  const VolumeFrame frames[] = {parse_frame("geographic"), parse_frame("geographic-agl"),
                                parse_frame("enu:44.27,-71.3,1917.25"), VolumeFrame{}};
  unsigned seed = 1;
  for (const auto& frame : frames) {
    const Volume v = random_volume(seed++, {7, 5, 3}, frame);
    const Volume back = parse_vdb(encode_vdb({&v}), "mem.vdb");
    expect_same(v, back);
    EXPECT_EQ(back.active_points, v.lattice.size());
  }
}

TEST(VdbRoundTrip, PicksGridsByNameAndDefaultsToTheFirst) {
  const Volume a = random_volume(11, {4, 4, 4}, parse_frame("geographic-agl"));
  Volume b = random_volume(12, {9, 2, 1}, parse_frame("geographic-agl"));
  const std::string bytes = encode_vdb({&a, &b});
  expect_same(parse_vdb(bytes, "m.vdb"), a);
  ReadOptions o;
  o.field = b.name;
  expect_same(parse_vdb(bytes, "m.vdb", o), b);
  o.field = "nothing";
  try {
    parse_vdb(bytes, "m.vdb", o);
    FAIL() << "no error";
  } catch (const io::FormatError& e) {
    EXPECT_EQ(std::string(e.what()), "m.vdb: no grid named 'nothing' (grids: 'field_11' (float), 'field_12' (float))");
  }
  const auto grids = vdb_grids(bytes, "m.vdb");
  ASSERT_EQ(grids.size(), 2u);
  EXPECT_EQ(grids[1].name, "field_12");
  EXPECT_EQ(grids[1].type, "float");
}

TEST(VdbRoundTrip, OptionsOverrideTheFileFrameAndUnits) {
  const Volume a = random_volume(3, {2, 3, 4}, parse_frame("geographic"));
  ReadOptions o;
  o.frame = parse_frame("geographic-agl");
  o.units = "dBm";
  const Volume back = parse_vdb(encode_vdb({&a}), "m.vdb", o);
  EXPECT_EQ(back.frame, *o.frame);
  EXPECT_EQ(back.units, "dBm");
}

TEST(VdbWrite, WritesAtomicallyAndNeverOverwritesWithoutForce) {
  test::TempDir dir;
  const auto path = dir.path() / "out.vdb";
  const Volume a = random_volume(5, {6, 6, 2}, parse_frame("enu:10,20,30"));
  write_vdb(path, {&a}, false);
  expect_same(read_volume(path), a);
  const Volume b = random_volume(6, {2, 2, 2}, parse_frame("geographic"));
  try {
    write_vdb(path, {&b}, false);
    FAIL() << "overwrote";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": exists (use --force to overwrite)");
  }
  expect_same(read_volume(path), a);
  write_vdb(path, {&b}, true);
  expect_same(read_volume(path), b);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()), 1);
}

TEST(VdbWrite, RejectsDuplicateOrEmptyNames) {
  Volume a = random_volume(1, {2, 2, 2}, VolumeFrame{});
  EXPECT_THROW(encode_vdb({&a, &a}), std::invalid_argument);
  a.name.clear();
  EXPECT_THROW(encode_vdb({&a}), std::invalid_argument);
}

TEST(VdbHostile, EveryTruncationIsAnErrorOrAVolume) {
  const Volume a = random_volume(21, {10, 9, 3}, parse_frame("geographic-agl"));
  const std::string bytes = encode_vdb({&a});
  for (std::size_t n = 0; n < bytes.size(); n += (n < 400 ? 1 : 13)) {
    expect_volume_or_one_line_error([&] { return parse_vdb(bytes.substr(0, n), "cut.vdb"); }, "cut.vdb",
                                    "length " + std::to_string(n));
  }
}

TEST(VdbHostile, CorruptBytesAreAnErrorOrAVolume) {
  const Volume a = random_volume(22, {8, 8, 8}, parse_frame("geographic"));
  const std::string bytes = encode_vdb({&a});
  std::mt19937 rng(2024);
  for (int trial = 0; trial < 300; ++trial) {
    std::string bad = bytes;
    const int flips = 1 + trial % 4;
    for (int f = 0; f < flips; ++f) {
      bad[std::uniform_int_distribution<std::size_t>(0, bad.size() - 1)(rng)] = static_cast<char>(rng());
    }
    expect_volume_or_one_line_error([&] { return parse_vdb(bad, "bad.vdb"); }, "bad.vdb", "trial " + std::to_string(trial));
  }
}

TEST(VdbHostile, NotAVdbFile) {
  for (const std::string& bytes : {std::string(), std::string("VDB"), std::string(100, 'x')}) {
    EXPECT_THROW(parse_vdb(bytes, "x.vdb"), io::FormatError);
  }
}

// ---- VTK image data ----

vtkNew<vtkImageData> image_of(const Volume& v, bool with_metadata) {
  vtkNew<vtkImageData> image;
  // A non-zero extent start, to check that the origin accounts for it.
  image->SetExtent(2, 2 + v.lattice.dims[0] - 1, -1, -1 + v.lattice.dims[1] - 1, 0, v.lattice.dims[2] - 1);
  image->SetOrigin(v.lattice.origin[0] - 2 * v.lattice.spacing[0], v.lattice.origin[1] + v.lattice.spacing[1],
                   v.lattice.origin[2]);
  image->SetSpacing(v.lattice.spacing.data());
  vtkNew<vtkFloatArray> a;
  a->SetName(v.name.c_str());
  a->SetNumberOfValues(static_cast<vtkIdType>(v.values.size()));
  for (std::size_t n = 0; n < v.values.size(); ++n) a->SetValue(static_cast<vtkIdType>(n), v.values[n]);
  image->GetPointData()->SetScalars(a);
  if (with_metadata) {
    auto add_string = [&](const std::string& key, const std::string& value) {
      vtkNew<vtkStringArray> s;
      s->SetName(key.c_str());
      s->InsertNextValue(value);
      image->GetFieldData()->AddArray(s);
    };
    add_string(keys::kFrame, v.frame.kind == FrameKind::kEnu ? "enu" : "geographic");
    add_string(keys::kHeight, v.frame.height == HeightRef::kGround ? "ground" : "datum");
    add_string(keys::kUnits, v.units);
    for (const auto& [k, value] : v.attributes) add_string(keys::kAttributePrefix + k, value);
    if (v.frame.kind == FrameKind::kEnu) {
      vtkNew<vtkDoubleArray> o;
      o->SetName(keys::kOrigin);
      o->SetNumberOfComponents(3);
      o->InsertNextTuple3(v.frame.origin_lat, v.frame.origin_lon, v.frame.origin_h);
      image->GetFieldData()->AddArray(o);
    }
  }
  return image;
}

std::string vti_bytes(vtkImageData* image, bool compressed, int mode) {
  vtkNew<vtkXMLImageDataWriter> w;
  w->SetInputData(image);
  w->WriteToOutputStringOn();
  if (!compressed) w->SetCompressorTypeToNone();
  w->SetDataMode(mode);
  w->Write();
  return w->GetOutputString();
}

std::string legacy_bytes(vtkImageData* image, bool binary) {
  vtkNew<vtkStructuredPoints> sp;
  sp->ShallowCopy(image);
  vtkNew<vtkStructuredPointsWriter> w;
  w->SetInputData(sp);
  w->WriteToOutputStringOn();
  if (binary) w->SetFileTypeToBinary();
  w->Write();
  return w->GetOutputStdString();
}

TEST(VtiRoundTrip, ReadsBackWhatVtkWrote) {
  const Volume v = random_volume(31, {5, 4, 3}, parse_frame("enu:44.27,-71.3,100"));
  const auto image = image_of(v, true);
  for (bool compressed : {false, true}) {
    for (int mode : {vtkXMLWriter::Ascii, vtkXMLWriter::Binary, vtkXMLWriter::Appended}) {
      const Volume back = parse_vti(vti_bytes(image, compressed, mode), "t.vti");
      EXPECT_EQ(back.frame, v.frame);
      EXPECT_EQ(back.units, v.units);
      EXPECT_EQ(back.attributes, v.attributes);
      EXPECT_EQ(back.lattice.dims, v.lattice.dims);
      for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(back.lattice.origin[a], v.lattice.origin[a], 1e-9);
        EXPECT_DOUBLE_EQ(back.lattice.spacing[a], v.lattice.spacing[a]);
      }
      if (mode != vtkXMLWriter::Ascii) {
        EXPECT_TRUE(std::equal(v.values.begin(), v.values.end(), back.values.begin()));
      } else {
        for (std::size_t n = 0; n < v.values.size(); ++n) EXPECT_NEAR(back.values[n], v.values[n], 1e-3);
      }
    }
  }
}

TEST(LegacyVtkRoundTrip, ReadsBackWhatVtkWrote) {
  const Volume v = random_volume(32, {6, 2, 4}, parse_frame("geographic-agl"));
  const auto image = image_of(v, true);
  for (bool binary : {false, true}) {
    const Volume back = parse_legacy_vtk(legacy_bytes(image, binary), "t.vtk");
    EXPECT_EQ(back.frame, v.frame);
    EXPECT_EQ(back.attributes, v.attributes);
    EXPECT_EQ(back.lattice.dims, v.lattice.dims);
    for (std::size_t n = 0; n < v.values.size(); ++n) {
      if (binary) {
        EXPECT_EQ(back.values[n], v.values[n]);
      } else {
        EXPECT_NEAR(back.values[n], v.values[n], 1e-3);
      }
    }
  }
}

TEST(VtkImage, NegativeSpacingIsUndoneByReversingTheAxis) {
  vtkNew<vtkImageData> image;
  image->SetDimensions(3, 2, 1);
  image->SetOrigin(10.0, 0.0, 0.0);
  image->SetSpacing(-1.0, 1.0, 1.0);  // x runs 10, 9, 8
  vtkNew<vtkShortArray> a;
  a->SetName("s");
  for (short x : {10, 9, 8, 110, 109, 108}) a->InsertNextValue(x);
  image->GetPointData()->SetScalars(a);
  const Volume v = parse_vti(vti_bytes(image, false, vtkXMLWriter::Ascii), "n.vti");
  EXPECT_EQ(v.lattice.origin[0], 8.0);
  EXPECT_EQ(v.lattice.spacing[0], 1.0);
  EXPECT_EQ(v.values, (std::vector<float>{8, 9, 10, 108, 109, 110}));
  EXPECT_EQ(v.frame.kind, FrameKind::kNone);
}

TEST(VtkImage, RefusesVectorsAndCellData) {
  vtkNew<vtkImageData> image;
  image->SetDimensions(2, 2, 2);
  vtkNew<vtkFloatArray> a;
  a->SetName("wind");
  a->SetNumberOfComponents(3);
  for (int n = 0; n < 8; ++n) a->InsertNextTuple3(n, n, n);
  image->GetPointData()->SetVectors(a);
  EXPECT_THROW(parse_vti(vti_bytes(image, false, vtkXMLWriter::Ascii), "v.vti"), io::FormatError);
  ReadOptions o;
  o.field = "wind";
  try {
    parse_vti(vti_bytes(image, false, vtkXMLWriter::Ascii), "v.vti", o);
    FAIL();
  } catch (const io::FormatError& e) {
    EXPECT_EQ(std::string(e.what()), "v.vti: array 'wind' has 3 components, expected 1");
  }
}

// ---- the real volume ----

std::filesystem::path hydrogen() { return test::shared_data() / "volume" / "hydrogen.vtk"; }

TEST(Hydrogen, DimensionsRangeAndName) {
  TERRAVOL_REQUIRE_SHARED(hydrogen());
  const Volume v = read_volume(hydrogen());
  EXPECT_EQ(v.name, "probability_density");
  EXPECT_EQ(v.lattice.dims, (std::array<int, 3>{64, 64, 64}));
  EXPECT_EQ(v.lattice.origin, (std::array<double, 3>{0.0, 0.0, 0.0}));
  EXPECT_EQ(v.lattice.spacing, (std::array<double, 3>{1.0, 1.0, 1.0}));
  EXPECT_EQ(v.frame.kind, FrameKind::kNone);
  const auto [lo, hi] = std::minmax_element(v.values.begin(), v.values.end());
  EXPECT_EQ(*lo, 0.0f);
  EXPECT_EQ(*hi, 1.0f);
  double sum = 0.0;
  for (float x : v.values) sum += x;
  EXPECT_NEAR(sum / v.values.size(), 0.0185242, 1e-6);
  ReadOptions o;
  o.frame = parse_frame("enu:45.5,6.5,1000");
  EXPECT_EQ(read_volume(hydrogen(), o).frame, *o.frame);
}

TEST(Hydrogen, EveryTruncationIsAnErrorOrAVolume) {
  TERRAVOL_REQUIRE_SHARED(hydrogen());
  const std::string bytes = slurp(hydrogen());
  std::vector<std::size_t> lengths;
  for (std::size_t n = 0; n < 700; ++n) lengths.push_back(n);  // every length through the header
  for (std::size_t n = 700; n < bytes.size(); n += bytes.size() / 37) lengths.push_back(n);
  for (std::size_t n = bytes.size() - 40; n < bytes.size(); ++n) lengths.push_back(n);  // inside the last values
  int errors = 0;
  for (std::size_t n : lengths) {
    bool failed = false;
    expect_volume_or_one_line_error(
        [&] {
          try {
            return parse_legacy_vtk(std::string_view(bytes).substr(0, n), "hydrogen.vtk");
          } catch (const io::FormatError&) {
            failed = true;
            throw;
          }
        },
        "hydrogen.vtk", "length " + std::to_string(n));
    errors += failed;
  }
  // Every cut before the last value is an error; cuts within the last value's digits read it short.
  EXPECT_GE(errors, static_cast<int>(lengths.size()) - 20);
}

TEST(Hydrogen, VtkPrintsNothingOnBadInput) {
  TERRAVOL_REQUIRE_SHARED(hydrogen());
  const std::string bytes = slurp(hydrogen());
  test::StderrCapture capture;
  EXPECT_THROW(parse_legacy_vtk(std::string_view(bytes).substr(0, bytes.size() / 2), "h.vtk"), io::FormatError);
  EXPECT_THROW(parse_vti("<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 1 0 1 0 1\"", "h.vti"), io::FormatError);
  EXPECT_EQ(capture.finish(), "");
}

TEST(LegacyVtkHostile, BadHeadersAreOneLineErrors) {
  const std::string head = "# vtk DataFile Version 3.0\ntitle\nASCII\n";
  const std::pair<std::string, std::string> cases[] = {
      {"", "not a legacy VTK file"},
      {"garbage\n", "not a legacy VTK file"},
      {"# vtk DataFile Version 3.0\ntitle\nTEXT\n", "third line must say ASCII or BINARY"},
      {head + "DATASET POLYDATA\nPOINTS 0 float\n", "legacy VTK dataset is POLYDATA, expected STRUCTURED_POINTS"},
      {head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 100000 100000 100000\n", "are too large"},
      {head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 99999999999999999999 1 1\n", "DIMENSIONS needs three integers"},
      {head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 0 2 2\n", "each must be at least 1"},
      {head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 100 100 100\n", "need more data than the file holds"},
      {head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\nORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 9\n",
       "POINT_DATA 9 does not match DIMENSIONS 2 2 2"},
      {head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 1\nORIGIN 0 0 0\nSPACING 1 1 1\n", "no point scalars"},
      {head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 1\nORIGIN 0 0 0\nSPACING 1 0 1\nPOINT_DATA 4\n"
              "SCALARS s float\nLOOKUP_TABLE default\n1 2 3 4\n",
       "spacing of axis 1 is 0"},
      {head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 1\nORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 4\n"
              "SCALARS s float\nLOOKUP_TABLE default\n1 2 x 4\n",
       ""},
      {head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 1\nORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 4\n"
              "FIELD f 1\nbig 1 1000000000000 float\n",
       ""},
  };
  for (const auto& [text, expected] : cases) {
    try {
      const Volume v = parse_legacy_vtk(text, "bad.vtk");
      ADD_FAILURE() << "read: " << text;
    } catch (const io::FormatError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("bad.vtk: ", 0), 0u) << what;
      EXPECT_NE(what.find(expected), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(VtiHostile, BadFilesAreOneLineErrors) {
  const Volume v = random_volume(41, {6, 5, 4}, parse_frame("geographic"));
  const auto image = image_of(v, true);
  for (bool compressed : {false, true}) {
    for (int mode : {vtkXMLWriter::Ascii, vtkXMLWriter::Binary, vtkXMLWriter::Appended}) {
      const std::string bytes = vti_bytes(image, compressed, mode);
      for (std::size_t n = 0; n < bytes.size(); n += 1 + bytes.size() / 150) {
        expect_volume_or_one_line_error([&] { return parse_vti(bytes.substr(0, n), "cut.vti"); }, "cut.vti",
                                        "mode " + std::to_string(mode) + " length " + std::to_string(n));
      }
    }
  }
  for (const std::string& text :
       {std::string(), std::string("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\">"),
        std::string("<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 99999 0 99999 0 99999\">"),
        std::string("<VTKFile type=\"ImageData\"><ImageData WholeExtent=\"0 9 0 9 0 9\">")}) {
    expect_volume_or_one_line_error([&] { return parse_vti(text, "x.vti"); }, "x.vti", text);
    EXPECT_THROW(parse_vti(text, "x.vti"), io::FormatError);
  }
}

TEST(ReadVolume, MissingUnknownAndMislabelledFiles) {
  test::TempDir dir;
  auto expect_error = [](const std::filesystem::path& p, const std::string& expected) {
    try {
      read_volume(p);
      ADD_FAILURE() << "read " << p;
    } catch (const io::FormatError& e) {
      EXPECT_EQ(std::string(e.what()), p.string() + ": " + expected);
    }
  };
  expect_error(dir.path() / "none.vdb", "no such file");
  expect_error(dir.path() / "x.raw", "unknown volume format (expected .vdb, .vti or .vtk)");
  std::filesystem::create_directory(dir.path() / "d.vti");
  expect_error(dir.path() / "d.vti", "is a folder, not a volume file");
  const auto dem = std::filesystem::path(TERRAVOL_SOURCE_DIR) / "data" / "dem" / "N45E006.hgt";
  const auto fake = dir.path() / "dem.vdb";
  std::filesystem::copy_file(dem, fake);
  expect_error(fake, "not a VDB file (bad magic number)");
  const auto fake_vtk = dir.path() / "dem.vtk";
  std::filesystem::copy_file(dem, fake_vtk);
  expect_error(fake_vtk, "not a legacy VTK file (no '# vtk DataFile Version' line)");
}

}  // namespace
}  // namespace terravol::volume
