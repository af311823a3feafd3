// VTK image data: XML .vti (vtkXMLImageDataReader) and legacy .vtk STRUCTURED_POINTS
// (vtkStructuredPointsReader), read from memory in an isolated child process (isolated.h),
// after a prescan of the header in this process. VTK reports problems to observers of the
// reader, its executive and its XML parser, and otherwise to the global output window (and
// vtkLogger, which prints to stderr: the child's stderr is /dev/null); the first error, or
// warning not known to be harmless, becomes the FormatError's message.
#include <vtkAbstractArray.h>
#include <vtkCellData.h>
#include <vtkCharArray.h>
#include <vtkCommand.h>
#include <vtkExecutive.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMatrix3x3.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkStructuredPoints.h>
#include <vtkStructuredPointsReader.h>
#include <vtkXMLImageDataReader.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "io/error.h"
#include "volume/isolated.h"
#include "volume/reader_common.h"
#include "volume/vtk_smp.h"
#include "volume/readers.h"

namespace terravol::volume {

namespace {

// Collects the errors and warnings of the objects it observes (the reader, its executive and,
// for XML, its parser), which keeps VTK from printing them.
class MessageObserver : public vtkCommand {
 public:
  static MessageObserver* New() { return new MessageObserver; }
  void Execute(vtkObject*, unsigned long event, void* data) override {
    const char* text = static_cast<const char*>(data);
    (event == vtkCommand::ErrorEvent ? errors : warnings).emplace_back(text ? text : "");
  }
  void observe(vtkObject* object) {
    if (!object) return;
    object->AddObserver(vtkCommand::ErrorEvent, this);
    object->AddObserver(vtkCommand::WarningEvent, this);
  }
  std::vector<std::string> errors, warnings;
};

// Collects what other VTK objects send to the global output window instead of printing it.
class CaptureWindow : public vtkOutputWindow {
 public:
  static CaptureWindow* New();
  vtkTypeMacro(CaptureWindow, vtkOutputWindow);
  void DisplayText(const char*) override {}
  void DisplayErrorText(const char* text) override { errors.emplace_back(text ? text : ""); }
  void DisplayWarningText(const char*) override {}
  // vtkDataReader reports a short ASCII array as a generic warning.
  void DisplayGenericWarningText(const char* text) override { errors.emplace_back(text ? text : ""); }
  void DisplayDebugText(const char*) override {}
  std::vector<std::string> errors;

 protected:
  CaptureWindow() = default;
};
vtkStandardNewMacro(CaptureWindow);

// Held by the parent around each isolated read, so that no other thread of ours is inside
// VTK's readers when it forks.
std::mutex& vtk_mutex() {
  static std::mutex m;
  return m;
}

// Installs a CaptureWindow while alive and holds the observer. Runs in the isolated child,
// which has one thread: no lock.
class ScopedCapture {
 public:
  ScopedCapture() : previous_(vtkOutputWindow::GetInstance()) {
    vtkOutputWindow::SetInstance(window_);
  }
  ~ScopedCapture() { vtkOutputWindow::SetInstance(previous_); }
  ScopedCapture(const ScopedCapture&) = delete;
  ScopedCapture& operator=(const ScopedCapture&) = delete;
  MessageObserver* observer() { return observer_; }
  // The first error, or the first warning that is not known to be harmless; empty when none.
  std::string problem() const {
    if (!observer_->errors.empty()) return observer_->errors.front();
    if (!window_->errors.empty()) return window_->errors.front();
    for (const auto& w : observer_->warnings) {
      if (w.find("Not all meta data was read") == std::string::npos) return w;
    }
    return {};
  }

 private:
  vtkSmartPointer<vtkOutputWindow> previous_;
  vtkNew<CaptureWindow> window_;
  vtkNew<MessageObserver> observer_;
};

// "ERROR: In FILE, line N\nvtkX (0x...): message\n\n" (or "Warning: In", "Generic Warning:
// In") -> "message", on one line.
std::string clean_vtk_message(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    const bool location = line.rfind("ERROR: In ", 0) == 0 || line.rfind("Warning: In ", 0) == 0 ||
                          line.rfind("Generic Warning: In ", 0) == 0;
    if (!line.empty() && !location) lines.push_back(line);
    start = end + 1;
  }
  std::string msg;
  for (const auto& l : lines) msg += (msg.empty() ? "" : " ") + l;
  const std::size_t p = msg.find("): ");
  if (p != std::string::npos && p < 80) msg = msg.substr(p + 3);
  return msg.empty() ? "unreadable" : detail::printable(msg, 300);
}

void throw_if_errors(const ScopedCapture& capture, const std::string& source) {
  const std::string problem = capture.problem();
  if (!problem.empty()) throw io::FormatError(source, clean_vtk_message(problem));
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// Splits a line into whitespace-separated words.
std::vector<std::string> words_of(std::string_view line) {
  std::vector<std::string> w;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    std::size_t j = i;
    while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
    if (j > i) w.emplace_back(line.substr(i, j - i));
    i = j;
  }
  return w;
}

std::optional<long long> to_integer(const std::string& s) {
  if (s.empty() || s.size() > 18) return std::nullopt;
  char* end = nullptr;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (*end != '\0') return std::nullopt;
  return v;
}

// Checks the legacy header before VTK sees it: the magic line, the dataset type and the
// dimensions against the file's size (every point's scalar takes at least one byte).
void prescan_legacy(std::string_view bytes, const std::string& source) {
  if (bytes.rfind("# vtk DataFile Version", 0) != 0) {
    throw io::FormatError(source, "not a legacy VTK file (no '# vtk DataFile Version' line)");
  }
  std::optional<std::array<long long, 3>> dims;
  std::size_t start = 0;
  int line_no = 0;
  while (start < bytes.size()) {
    std::size_t end = bytes.find('\n', start);
    if (end == std::string_view::npos) end = bytes.size();
    const std::string_view line = bytes.substr(start, end - start);
    start = end + 1;
    if (++line_no <= 2) continue;  // magic line, title
    const auto w = words_of(line.substr(0, 256));
    if (w.empty()) continue;
    const std::string key = lower(w[0]);
    if (line_no == 3 && key != "ascii" && key != "binary") {
      throw io::FormatError(source, "third line must say ASCII or BINARY");
    }
    if (key == "dataset") {
      if (w.size() < 2) throw io::FormatError(source, "DATASET without a type");
      if (lower(w[1]) != "structured_points") {
        throw io::FormatError(source, "legacy VTK dataset is " + detail::printable(w[1]) + ", expected STRUCTURED_POINTS");
      }
    } else if (key == "dimensions") {
      std::array<long long, 3> d{0, 0, 0};
      for (int a = 0; a < 3; ++a) {
        const auto v = a + 1 < static_cast<int>(w.size()) ? to_integer(w[a + 1]) : std::nullopt;
        if (!v) throw io::FormatError(source, "DIMENSIONS needs three integers");
        d[a] = *v;
      }
      detail::check_dims(d, bytes.size(), source);
      dims = d;
    } else if (key == "point_data" || key == "cell_data") {
      if (key == "cell_data") continue;
      const auto n = w.size() > 1 ? to_integer(w[1]) : std::nullopt;
      if (!n) throw io::FormatError(source, "POINT_DATA needs a count");
      if (dims && *n != (*dims)[0] * (*dims)[1] * (*dims)[2]) {
        throw io::FormatError(source, "POINT_DATA " + detail::printable(w[1]) + " does not match DIMENSIONS " + std::to_string((*dims)[0]) +
                                          " " + std::to_string((*dims)[1]) + " " + std::to_string((*dims)[2]));
      }
      return;  // the data follow; VTK reads them
    }
  }
}

// The WholeExtent of a .vti against the file's size.
void prescan_vti(std::string_view bytes, const std::string& source) {
  const std::string_view head = bytes.substr(0, std::min<std::size_t>(bytes.size(), 4096));
  if (head.find("<VTKFile") == std::string_view::npos) throw io::FormatError(source, "not a VTK XML file (no <VTKFile>)");
  const std::size_t type = head.find("type=\"");
  if (type == std::string_view::npos || head.substr(type + 6, 10) != "ImageData\"") {
    const std::size_t q = type == std::string_view::npos ? type : head.find('"', type + 6);
    const std::string name = q == std::string_view::npos ? "unknown" : detail::printable(head.substr(type + 6, q - type - 6));
    throw io::FormatError(source, "VTK XML file of type " + name + ", expected ImageData");
  }
  const std::size_t ext = head.find("WholeExtent=\"");
  if (ext == std::string_view::npos) throw io::FormatError(source, "no WholeExtent");
  const std::size_t q = head.find('"', ext + 13);
  if (q == std::string_view::npos) throw io::FormatError(source, "unterminated WholeExtent");
  const auto w = words_of(head.substr(ext + 13, q - ext - 13));
  if (w.size() != 6) throw io::FormatError(source, "WholeExtent needs six integers");
  std::array<long long, 6> e{};
  for (int n = 0; n < 6; ++n) {
    const auto v = to_integer(w[n]);
    if (!v || std::llabs(*v) > (1LL << 40)) throw io::FormatError(source, "WholeExtent needs six integers");
    e[n] = *v;
  }
  // Compressed data may be far smaller than the values; raw or base64 values take >= 1 byte.
  const bool compressed = head.find("compressor=") != std::string_view::npos;
  const std::size_t bound = compressed ? kMaxPoints : bytes.size();
  detail::check_dims({e[1] - e[0] + 1, e[3] - e[2] + 1, e[5] - e[4] + 1}, bound, source);
}

detail::FileMetadata metadata_of(vtkFieldData* fd) {
  detail::FileMetadata m;
  if (!fd) return m;
  auto string_of = [fd](const char* key) -> std::optional<std::string> {
    auto* a = vtkStringArray::SafeDownCast(fd->GetAbstractArray(key));
    if (!a || a->GetNumberOfValues() < 1) return std::nullopt;
    return a->GetValue(0);
  };
  m.frame = string_of(keys::kFrame);
  m.height = string_of(keys::kHeight);
  m.units = string_of(keys::kUnits);
  if (auto* o = vtkDataArray::SafeDownCast(fd->GetAbstractArray(keys::kOrigin))) {
    if (o->GetNumberOfValues() == 3) {
      m.origin = std::array<double, 3>{o->GetComponent(0, 0), 0.0, 0.0};
      for (int n = 0; n < 3; ++n) {
        const vtkIdType t = o->GetNumberOfComponents() == 3 ? 0 : n;
        const int c = o->GetNumberOfComponents() == 3 ? n : 0;
        (*m.origin)[n] = o->GetComponent(t, c);
      }
    }
  }
  const std::string prefix = keys::kAttributePrefix;
  for (int n = 0; n < fd->GetNumberOfArrays(); ++n) {
    auto* a = vtkStringArray::SafeDownCast(fd->GetAbstractArray(n));
    if (!a || !a->GetName() || a->GetNumberOfValues() < 1) continue;
    const std::string name = a->GetName();
    if (name.rfind(prefix, 0) == 0) m.attributes[name.substr(prefix.size())] = a->GetValue(0);
  }
  return m;
}

// The scalar volume of an image data set.
Volume volume_of(vtkImageData* image, const std::string& source, const ReadOptions& options) {
  if (!image) throw io::FormatError(source, "no image data");
  if (vtkMatrix3x3* d = image->GetDirectionMatrix()) {
    if (!d->IsIdentity()) throw io::FormatError(source, "rotated image data (a direction matrix) is not supported");
  }
  int extent[6];
  image->GetExtent(extent);
  detail::check_dims({static_cast<long long>(extent[1]) - extent[0] + 1, static_cast<long long>(extent[3]) - extent[2] + 1,
                      static_cast<long long>(extent[5]) - extent[4] + 1},
                     kMaxPoints, source);
  Volume v;
  vtkPointData* pd = image->GetPointData();
  vtkDataArray* array = nullptr;
  if (!options.field.empty()) {
    vtkAbstractArray* a = pd ? pd->GetAbstractArray(options.field.c_str()) : nullptr;
    if (!a) throw io::FormatError(source, "no point-data array named '" + detail::printable(options.field) + "'");
    array = vtkDataArray::SafeDownCast(a);
    if (!array) throw io::FormatError(source, "point-data array '" + detail::printable(options.field) + "' is not numeric");
  } else if (pd) {
    array = pd->GetScalars();
    for (int n = 0; !array && n < pd->GetNumberOfArrays(); ++n) {
      vtkDataArray* a = pd->GetArray(n);
      if (a && a->GetNumberOfComponents() == 1) array = a;
    }
  }
  if (!array) {
    const bool cells = image->GetCellData() && image->GetCellData()->GetNumberOfArrays() > 0;
    throw io::FormatError(source, cells ? "no point scalars (cell data is not supported)" : "no point scalars");
  }
  if (array->GetNumberOfComponents() != 1) {
    throw io::FormatError(source, "array '" + detail::printable(array->GetName() ? array->GetName() : "") + "' has " +
                                      std::to_string(array->GetNumberOfComponents()) + " components, expected 1");
  }
  v.name = array->GetName() ? array->GetName() : "scalars";
  v.lattice.dims = {extent[1] - extent[0] + 1, extent[3] - extent[2] + 1, extent[5] - extent[4] + 1};
  if (static_cast<std::size_t>(array->GetNumberOfTuples()) != v.lattice.size()) {
    throw io::FormatError(source, "array '" + detail::printable(v.name) + "' has " + std::to_string(array->GetNumberOfTuples()) +
                                      " values for " + std::to_string(v.lattice.size()) + " points");
  }
  double origin[3], spacing[3];
  image->GetOrigin(origin);
  image->GetSpacing(spacing);
  for (int a = 0; a < 3; ++a) {
    v.lattice.spacing[a] = spacing[a];
    v.lattice.origin[a] = origin[a] + extent[2 * a] * spacing[a];
  }
  detail::check_geometry(v.lattice, source);
  v.values.resize(v.lattice.size());
  if (auto* f = vtkFloatArray::SafeDownCast(array)) {
    std::memcpy(v.values.data(), f->GetPointer(0), v.values.size() * sizeof(float));
  } else {
    for (std::size_t n = 0; n < v.values.size(); ++n) {
      v.values[n] = static_cast<float>(array->GetComponent(static_cast<vtkIdType>(n), 0));
    }
  }
  v.active_points = v.values.size();
  detail::normalise_axes(v);
  detail::apply_metadata(v, metadata_of(image->GetFieldData()), options, source);
  return v;
}

Volume read_legacy_vtk(std::string_view bytes, const std::string& source, const ReadOptions& options) {
  detail::use_sequential_vtk_smp();  // no TBB in the forked child
  ScopedCapture capture;
  vtkNew<vtkCharArray> input;
  // Borrowed memory (save = 1: VTK does not free it); the reader does not write to it.
  input->SetArray(const_cast<char*>(bytes.data()), static_cast<vtkIdType>(bytes.size()), 1);
  vtkNew<vtkStructuredPointsReader> reader;
  capture.observer()->observe(reader);
  capture.observer()->observe(reader->GetExecutive());
  reader->ReadFromInputStringOn();
  reader->SetInputArray(input);
  reader->Update();
  throw_if_errors(capture, source);
  return volume_of(reader->GetOutput(), source, options);
}

Volume read_vti(std::string_view bytes, const std::string& source, const ReadOptions& options) {
  detail::use_sequential_vtk_smp();  // no TBB in the forked child
  ScopedCapture capture;
  vtkNew<vtkXMLImageDataReader> reader;
  capture.observer()->observe(reader);
  capture.observer()->observe(reader->GetExecutive());
  reader->SetReaderErrorObserver(capture.observer());
  reader->SetParserErrorObserver(capture.observer());
  reader->ReadFromInputStringOn();
  reader->SetInputString(std::string(bytes));
  reader->Update();
  throw_if_errors(capture, source);
  return volume_of(reader->GetOutput(), source, options);
}

}  // namespace

// VTK 9.1's readers crash on some truncated files (an appended .vti cut inside its field
// data: tests/volume/readers_test.cpp, VtiHostile), so they run in a child process.
Volume parse_legacy_vtk(std::string_view bytes, const std::string& source, const ReadOptions& options) {
  prescan_legacy(bytes, source);
  std::lock_guard<std::mutex> lock(vtk_mutex());
  return detail::parse_isolated(bytes, source, "VTK", [&] { return read_legacy_vtk(bytes, source, options); });
}

Volume parse_vti(std::string_view bytes, const std::string& source, const ReadOptions& options) {
  prescan_vti(bytes, source);
  std::lock_guard<std::mutex> lock(vtk_mutex());
  return detail::parse_isolated(bytes, source, "VTK", [&] { return read_vti(bytes, source, options); });
}

}  // namespace terravol::volume
