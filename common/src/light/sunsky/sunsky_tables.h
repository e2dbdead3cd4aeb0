// The sun/sky model's numeric tables (common/data/sunsky/*.txt), embedded in the library at build
// time so that nothing is read from disk at run time.
#pragma once

#include <string_view>
#include <vector>

namespace tessera::sunsky {

namespace detail {
/// One embedded file (defined in the generated sunsky_tables_data.cpp).
struct EmbeddedTable {
  std::string_view name;
  std::string_view text;
};
extern const EmbeddedTable kEmbeddedTables[];
extern const int kNumEmbeddedTables;
}  // namespace detail

/// Full text of the embedded table `name` (file name without ".txt"); empty if there is none.
std::string_view table_text(std::string_view name);

/// The numbers of table `name` in file order ('#' comment lines skipped). Checks (TESSERA_CHECK)
/// that the table exists and holds exactly `expected_count` values. Parses on every call: callers
/// keep the result (the models build their tables once, in function-local statics).
std::vector<double> table_values(std::string_view name, size_t expected_count);

}  // namespace tessera::sunsky
