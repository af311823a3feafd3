// A mosaic of DEM tiles presented as one geographic grid, loaded lazily.
#pragma once

#include <cstddef>
#include <filesystem>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "io/dem_file.h"
#include "io/grid.h"

namespace terravol::io {

// One input file placed in the mosaic's sample lattice.
struct MosaicTile {
  std::filesystem::path path;
  Format format = Format::kSrtm;
  int rows = 0, cols = 0;  // of the tile as presented (geographic)
  int row0 = 0, col0 = 0;  // its first sample in the mosaic lattice
  Georef georef;           // geographic
  bool extent_from_name = false;  // known from the SRTM/SDF file name; checked when loaded
};

// A rectangle of the mosaic's bounding box that no tile covers.
struct MosaicGap {
  int row0 = 0, col0 = 0, rows = 0, cols = 0;
  double south = 0, north = 0, west = 0, east = 0;  // degrees, sample positions
};

// The mosaic lattice is the tiles' common geographic spacing: tiles must share it (to one
// part in 10^6) and lie on it (to a hundredth of a sample). Projected tiles are resampled to
// geographic first (to_geographic), so in practice a projected file mosaics only alone.
// Where tiles overlap (SRTM and DTED neighbours share their edge samples) the first tile in
// input order provides the sample; the others' copies are not read.
//
// Laziness: open() learns each tile's extent from its name (SRTM N44W072, SDF 40_41_111_112,
// compressed or not) and, for .hgt, its size on disk or the size a .hgt.gz, .hgt.xz or
// .hgt.zip records (compressed.h, recorded_size), without reading it; other tiles (.hgt.bz2:
// bzip2 records no size) are read once at open() to learn their extent and kept in the cache.
// Decoded tiles live in a cache of at most `cache_tiles` tiles, so memory is bounded by the window
// and the cache, not by the number of input files. Reads are safe on any number of threads at once:
// the cache has its own lock, held only to look a tile up or put it in, never while a tile decodes
// (a reader of cached tiles need not wait for another thread's decode), and a caller keeps the
// tiles it reads alive while another thread's read evicts them. Two threads that miss the same tile
// both decode it. read_window decodes the tiles it needs in parallel itself.
class Mosaic {
 public:
  // inputs: files and directories (a directory contributes every file in it whose name has a
  // DEM extension, compressed or not (format_from_name), in name order). Throws FormatError for an unreadable input, an empty
  // directory, an unknown format, tiles of different spacing or off the lattice.
  static Mosaic open(const std::vector<std::filesystem::path>& inputs, const ReadOptions& options = {},
                     std::size_t cache_tiles = 4);

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  const Georef& georef() const { return georef_; }  // geographic; row 0 north
  const std::vector<MosaicTile>& tiles() const { return tiles_; }
  const std::vector<MosaicGap>& gaps() const { return gaps_; }
  std::size_t gap_samples() const;

  // The samples of rows [row0, row0 + n_rows) and columns [col0, col0 + n_cols) of the
  // lattice, voids marked kVoid (not filled) and samples no tile covers kOutside. The window
  // may extend past the mosaic (those samples are kOutside). Loads only the tiles it
  // overlaps. Throws FormatError for an empty or absurd window and for tiles that fail to load.
  Grid read_window(int row0, int col0, int n_rows, int n_cols) const;
  // The same window when every tile it needs is in the cache, without loading any; nullopt when
  // one is not (for a caller that must not wait for a decode). Throws as read_window does for
  // an empty or absurd window.
  std::optional<Grid> read_cached_window(int row0, int col0, int n_rows, int n_cols) const;

  // Tile i decoded (geographic, voids marked), from the cache or loaded now.
  std::shared_ptr<const Grid> tile_grid(std::size_t i) const;
  // How many tile loads have happened (cache misses), for tests and stats.
  std::size_t loads() const;

 private:
  Mosaic() = default;
  std::vector<MosaicTile> tiles_;
  std::vector<MosaicGap> gaps_;
  ReadOptions options_;
  Georef georef_;
  int rows_ = 0, cols_ = 0;
  std::size_t cache_capacity_ = 4;
  struct Cached {
    std::size_t tile;
    std::shared_ptr<const Grid> grid;
  };
  struct Cache {
    std::mutex mutex;         // guards the two below
    std::list<Cached> tiles;  // most recently used first
    std::size_t loads = 0;
  };
  std::unique_ptr<Cache> cache_ = std::make_unique<Cache>();  // behind a pointer: Mosaic moves
  // A freshly loaded tile counted and put in (or the copy another thread put in meanwhile).
  std::shared_ptr<const Grid> cache_insert(std::size_t tile, Grid grid) const;
  // The cached tile, made most recently used, or null (nothing loaded).
  std::shared_ptr<const Grid> cached(std::size_t tile) const;
  std::optional<Grid> read_window(int row0, int col0, int n_rows, int n_cols, bool may_load) const;
  // Tile i read and checked against the extent its name gave (no cache: safe on any thread).
  Grid load_tile(std::size_t i) const;
};

// Loads one DEM file as a geographic grid (read_dem, then to_geographic when projected).
Grid read_geographic(const std::filesystem::path& path, const ReadOptions& options = {});

}  // namespace terravol::io
