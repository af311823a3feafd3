#include "app/output/write_file.h"

#include <unistd.h>

#include <fstream>
#include <stdexcept>
#include <string>

namespace terravol::app::output {

void write_file_atomically(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes,
                           bool overwrite) {
  if (!overwrite && std::filesystem::exists(path)) {
    throw std::runtime_error(path.string() + ": exists (use --force to overwrite)");
  }
  std::filesystem::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      throw std::runtime_error(path.string() + ": cannot write");
    }
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace terravol::app::output
