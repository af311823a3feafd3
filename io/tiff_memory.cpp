#include "io/tiff_memory.h"


#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <limits>

namespace terravol::io::tiff {

namespace {

std::uint64_t file_size(const MemoryFile& f) { return f.sink ? f.sink->size() : f.data.size(); }

tmsize_t mem_read(thandle_t h, void* buf, tmsize_t n) {
  auto* f = static_cast<MemoryFile*>(h);
  const std::uint64_t size = file_size(*f);
  if (n <= 0 || f->pos >= size) return 0;
  const std::uint64_t count = std::min<std::uint64_t>(static_cast<std::uint64_t>(n), size - f->pos);
  const std::uint8_t* base = f->sink ? f->sink->data() : f->data.data();
  std::memcpy(buf, base + f->pos, static_cast<std::size_t>(count));
  f->pos += count;
  return static_cast<tmsize_t>(count);
}

tmsize_t mem_write(thandle_t h, void* buf, tmsize_t n) {
  auto* f = static_cast<MemoryFile*>(h);
  if (f->sink == nullptr || n < 0) return 0;  // opened for reading
  const auto count = static_cast<std::uint64_t>(n);
  if (f->pos + count > f->sink->size()) f->sink->resize(static_cast<std::size_t>(f->pos + count));
  std::memcpy(f->sink->data() + f->pos, buf, static_cast<std::size_t>(count));
  f->pos += count;
  return n;
}

toff_t mem_seek(thandle_t h, toff_t off, int whence) {
  auto* f = static_cast<MemoryFile*>(h);
  std::uint64_t base = 0;
  switch (whence) {
    case SEEK_SET:
      f->pos = off;
      return f->pos;
    case SEEK_CUR:
      base = f->pos;
      break;
    case SEEK_END:
      base = file_size(*f);
      break;
    default:
      return static_cast<toff_t>(-1);
  }
  // libtiff passes negative relative offsets as two's complement.
  if (static_cast<std::int64_t>(off) < 0) {
    const std::uint64_t back = std::uint64_t{0} - off;
    if (back > base) return static_cast<toff_t>(-1);
    f->pos = base - back;
  } else {
    if (off > std::numeric_limits<std::uint64_t>::max() - base) return static_cast<toff_t>(-1);
    f->pos = base + off;
  }
  return f->pos;
}

int mem_close(thandle_t) { return 0; }
toff_t mem_size(thandle_t h) { return file_size(*static_cast<MemoryFile*>(h)); }

int mem_map(thandle_t h, void** base, toff_t* size) {
  auto* f = static_cast<MemoryFile*>(h);
  if (f->sink) return 0;  // a growing file is not mapped
  // Opened read-only: libtiff never writes through the mapping.
  *base = const_cast<std::uint8_t*>(f->data.data());
  *size = f->data.size();
  return 1;
}

void mem_unmap(thandle_t, void*, toff_t) {}

void record(Diagnostics* d, const char* module, const char* fmt, va_list ap) {
  char buf[512];
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  std::string text = (module && *module) ? std::string(module) + ": " + buf : std::string(buf);
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  d->last_error = std::move(text);
}

int on_tiff_error(TIFF*, void* user, const char* module, const char* fmt, va_list ap) {
  record(static_cast<Diagnostics*>(user), module, fmt, ap);
  return 1;  // handled: libtiff's global handler (stderr) is not called
}

int on_tiff_warning(TIFF*, void*, const char*, const char*, va_list) { return 1; }

void on_geotiff_message(GTIF* gt, int level, const char* fmt, ...) {
  if (level != LIBGEOTIFF_ERROR || gt == nullptr) return;
  auto* d = static_cast<Diagnostics*>(GTIFGetUserData(gt));
  if (d == nullptr) return;
  va_list ap;
  va_start(ap, fmt);
  record(d, "libgeotiff", fmt, ap);
  va_end(ap);
}

// GDAL_NODATA and GDAL_METADATA are not in libtiff 4.5's tag table; without this they would
// be read as anonymous tags and could not be written. Chained after libgeotiff's extender,
// which registers the GeoTIFF tags.
TIFFExtendProc g_parent_extender = nullptr;

void extend_tags(TIFF* tif) {
  static const TIFFFieldInfo kFields[] = {
      {TIFFTAG_GDAL_NODATA, TIFF_VARIABLE, TIFF_VARIABLE, TIFF_ASCII, FIELD_CUSTOM, 1, 0,
       const_cast<char*>("GDALNoDataValue")},
      {kGdalMetadata, TIFF_VARIABLE, TIFF_VARIABLE, TIFF_ASCII, FIELD_CUSTOM, 1, 0,
       const_cast<char*>("GDALMetadata")}};
  TIFFMergeFieldInfo(tif, kFields, 2);
  if (g_parent_extender) g_parent_extender(tif);
}

void register_tags_once() {
  static const bool done = [] {
    XTIFFInitialize();
    g_parent_extender = TIFFSetTagExtender(extend_tags);
    return true;
  }();
  (void)done;
}

struct OptionsFreer {
  void operator()(TIFFOpenOptions* o) const { TIFFOpenOptionsFree(o); }
};

}  // namespace

TiffPtr open(MemoryFile& file, const char* mode, const std::string& name, Diagnostics& diag, tmsize_t max_alloc) {
  register_tags_once();
  std::unique_ptr<TIFFOpenOptions, OptionsFreer> options(TIFFOpenOptionsAlloc());
  if (!options) {
    diag.last_error = "out of memory";
    return nullptr;
  }
  TIFFOpenOptionsSetErrorHandlerExtR(options.get(), on_tiff_error, &diag);
  TIFFOpenOptionsSetWarningHandlerExtR(options.get(), on_tiff_warning, nullptr);
  TIFFOpenOptionsSetMaxSingleMemAlloc(options.get(), max_alloc);
  return TiffPtr(TIFFClientOpenExt(name.c_str(), mode, &file, mem_read, mem_write, mem_seek, mem_close, mem_size,
                                   mem_map, mem_unmap, options.get()));
}

GtifPtr open_keys(TIFF* tif, Diagnostics& diag) { return GtifPtr(GTIFNewEx(tif, on_geotiff_message, &diag)); }

}  // namespace terravol::io::tiff
