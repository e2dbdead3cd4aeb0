// A file mapped read-only into memory: its bytes as a string_view without reading them into the
// heap, so that a bundle of gigabytes is inspected, unpacked or sent without a copy of it.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace tessera {

class MappedFile {
 public:
  /// Maps `path`; throws std::runtime_error naming it when it cannot be opened or mapped.
  explicit MappedFile(const std::string& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  std::string_view bytes() const { return {static_cast<const char*>(data_), size_}; }
  size_t size() const { return size_; }

 private:
  void* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace tessera
