#include "app/output/write_file.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
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

void check_output_path(const std::filesystem::path& path, const std::string& option, const std::string& extension,
                       bool overwrite) {
  const std::string s = path.string();
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (!extension.empty() && ext != extension) throw std::runtime_error(option + " " + s + ": expected a " + extension + " file name");
  if (!overwrite && std::filesystem::exists(path)) throw std::runtime_error(s + ": exists (use --force to overwrite)");
  const auto folder = path.parent_path();
  if (!folder.empty() && !std::filesystem::is_directory(folder)) {
    throw std::runtime_error(option + " " + s + ": folder " + folder.string() + " does not exist");
  }
}

}  // namespace terravol::app::output
