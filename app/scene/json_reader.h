// Reading user-written JSON documents (scene files, camera paths) with one-line errors that
// name the document and the path of the offending value, e.g.
// "scene.json: volumes[0].slices[1].agl: must be within [-100000, 100000], is 1e+06".
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <set>
#include <stdexcept>
#include <string>

namespace terravol::app::scene {

// "%g" of a number, for messages.
inline std::string format_number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

class JsonReader {
 public:
  // source: the document's name in messages; noun: what its object members are called there
  // ("key", "field").
  JsonReader(std::string source, std::string noun) : source_(std::move(source)), noun_(std::move(noun)) {}

  // Throws std::invalid_argument("SOURCE: WHERE: WHAT").
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw std::invalid_argument(source_ + ": " + where + ": " + what);
  }

  // j must be an object whose members are all in `allowed`.
  void only_keys(const nlohmann::json& j, const std::string& where, std::initializer_list<const char*> allowed) const {
    if (!j.is_object()) fail(where.empty() ? "(top level)" : where, "expected an object");
    const std::set<std::string> ok(allowed.begin(), allowed.end());
    for (const auto& [key, value] : j.items()) {
      if (ok.count(key) == 0) {
        std::string list;
        for (const char* k : allowed) list += std::string(list.empty() ? "" : ", ") + k;
        fail(join(where, key), "unknown " + noun_ + " (known: " + list + ")");
      }
    }
  }
  const nlohmann::json& required(const nlohmann::json& j, const std::string& where, const char* key) const {
    if (!j.contains(key)) fail(where.empty() ? "(top level)" : where, std::string("missing \"") + key + "\"");
    return j[key];
  }
  // A finite number within [lo, hi].
  double number(const nlohmann::json& j, const std::string& where, double lo, double hi) const {
    if (!j.is_number()) fail(where, "expected a number, got " + j.dump());
    const double v = j.get<double>();
    if (!std::isfinite(v) || v < lo || v > hi) {
      fail(where, "must be within [" + format_number(lo) + ", " + format_number(hi) + "], is " + format_number(v));
    }
    return v;
  }
  bool boolean(const nlohmann::json& j, const std::string& where) const {
    if (!j.is_boolean()) fail(where, "expected true or false, got " + j.dump());
    return j.get<bool>();
  }
  std::string string(const nlohmann::json& j, const std::string& where) const {
    if (!j.is_string() || j.get<std::string>().empty()) fail(where, "expected a non-empty string, got " + j.dump());
    return j.get<std::string>();
  }

  static std::string join(const std::string& where, const std::string& key) {
    return where.empty() ? key : where + "." + key;
  }
  static std::string at(const std::string& where, std::size_t k) { return where + "[" + std::to_string(k) + "]"; }

 private:
  std::string source_, noun_;
};

}  // namespace terravol::app::scene
