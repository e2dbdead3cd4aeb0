#include "light/sunsky/sunsky_tables.h"

#include "tessera/core/check.h"

#include <cstdlib>
#include <string>

namespace tessera::sunsky {

std::string_view table_text(std::string_view name) {
  for (int i = 0; i < detail::kNumEmbeddedTables; ++i)
    if (detail::kEmbeddedTables[i].name == name) return detail::kEmbeddedTables[i].text;
  return {};
}

std::vector<double> table_values(std::string_view name, size_t expected_count) {
  std::string_view text = table_text(name);
  TESSERA_CHECK(!text.empty());
  std::vector<double> out;
  out.reserve(expected_count);
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string line(text.substr(pos, end - pos));
    pos = end + 1;
    size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const char* s = line.c_str() + first;
    char* next = nullptr;
    for (double v = std::strtod(s, &next); next != s; v = std::strtod(s, &next)) {
      out.push_back(v);
      s = next;
    }
  }
  TESSERA_CHECK(out.size() == expected_count);
  return out;
}

}  // namespace tessera::sunsky
