// A strict reader of JSON objects for the protocol's messages: records the first error, naming the
// field and what it should have been; unknown fields are errors. Private to the farm library.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace tessera::json_fields {

using nlohmann::json;

// Whether a JSON number is an integer that T holds: 2.5, 1e30 and 2^64 (which the parser keeps as a
// double) are not.
template <class T>
bool integer_fits(const json& v) {
  if (v.is_number_unsigned()) return v.get<uint64_t>() <= uint64_t(std::numeric_limits<T>::max());
  if (v.is_number_integer()) {
    const int64_t i = v.get<int64_t>();
    return i >= int64_t(std::numeric_limits<T>::min()) && (i < 0 || uint64_t(i) <= uint64_t(std::numeric_limits<T>::max()));
  }
  return false;
}

// Strict field reader: records the first error, names the field and what it should have been. A
// number out of its field's range is told apart from a malformed request (out_of_range()): the
// request is well-formed, only the value cannot be had, as with the limits check_job_limits applies.
class Fields {
 public:
  Fields(const json& j, std::string& error, const char* what) : j_(j), error_(error), what_(what) {
    if (!j.is_object()) fail(std::string(what) + ": expected a JSON object");
  }
  bool ok() const { return error_.empty(); }
  bool out_of_range() const { return out_of_range_; }

  template <class T>
  void get(const char* name, T& out, bool required = false) {
    seen_.insert(name);
    if (!ok()) return;
    auto it = j_.find(name);
    if (it == j_.end() || it->is_null()) {
      if (required) fail(std::string(what_) + ": missing field '" + name + "'");
      return;
    }
    try {
      if constexpr (std::is_same_v<T, bool>) {
        if (!it->is_boolean()) throw std::invalid_argument("true or false");
        out = it->template get<bool>();
      } else if constexpr (std::is_integral_v<T>) {
        if (!it->is_number()) throw std::invalid_argument("an integer");
        if (!integer_fits<T>(*it)) return fail_range(name, *it, std::numeric_limits<T>::min(), std::numeric_limits<T>::max());
        out = it->is_number_unsigned() ? T(it->template get<uint64_t>()) : T(it->template get<int64_t>());
      } else if constexpr (std::is_floating_point_v<T>) {
        if (!it->is_number()) throw std::invalid_argument("a number");
        out = it->template get<T>();
      } else if constexpr (std::is_same_v<T, std::string>) {
        if (!it->is_string()) throw std::invalid_argument("a string");
        out = it->template get<std::string>();
      } else {
        out = it->template get<T>();
      }
    } catch (const std::exception& e) {
      fail(std::string(what_) + ": field '" + name + "' must be " + e.what());
    }
  }
  /// Absent or null leaves `out` empty.
  template <class T>
  void get(const char* name, std::optional<T>& out) {
    T value{};
    const bool present = j_.is_object() && j_.contains(name) && !j_[name].is_null();
    get(name, value);
    if (present && ok()) out = value;
  }
  void get_strings(const char* name, std::map<std::string, std::string>& out) {
    seen_.insert(name);
    if (!ok()) return;
    auto it = j_.find(name);
    if (it == j_.end() || it->is_null()) return;
    if (!it->is_object()) return fail(std::string(what_) + ": field '" + name + "' must be an object of strings");
    for (auto& [k, v] : it->items()) {
      if (v.is_string()) out[k] = v.get<std::string>();
      else if (v.is_number() || v.is_boolean()) out[k] = v.dump();
      else return fail(std::string(what_) + ": field '" + name + "." + k + "' must be a string");
    }
  }
  void get_list(const char* name, std::vector<std::string>& out) {
    seen_.insert(name);
    if (!ok()) return;
    auto it = j_.find(name);
    if (it == j_.end() || it->is_null()) return;
    if (!it->is_array()) return fail(std::string(what_) + ": field '" + name + "' must be an array of strings");
    for (auto& v : *it) {
      if (!v.is_string()) return fail(std::string(what_) + ": field '" + name + "' must be an array of strings");
      out.push_back(v.get<std::string>());
    }
  }
  /// Unknown fields are errors: a misspelt "sp" must not render the scene's default spp.
  void finish() {
    if (!ok()) return;
    for (auto& [k, v] : j_.items())
      if (!seen_.count(k)) return fail(std::string(what_) + ": unknown field '" + k + "'");
  }
  void fail(const std::string& msg) {
    if (error_.empty()) error_ = msg;
  }
  void fail_range(const char* name, const json& value, int64_t min, uint64_t max) {
    if (!ok()) return;
    out_of_range_ = true;
    fail(std::string(what_) + ": field '" + name + "' must be an integer in " + std::to_string(min) + ".." +
         std::to_string(max) + ", not " + value.dump());
  }

 private:
  const json& j_;
  std::string& error_;
  const char* what_;
  bool out_of_range_ = false;
  std::set<std::string> seen_;
};

}  // namespace tessera::json_fields
