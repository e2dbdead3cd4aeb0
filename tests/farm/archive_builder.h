// Builds tar, tar.gz and zip archives in memory with libarchive, including the entries a hostile
// bundle would hold (links, devices, escaping paths), for the bundle tests.
#pragma once

#include <archive.h>
#include <archive_entry.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

namespace tessera::test {

class ArchiveBuilder {
 public:
  enum class Format { TarGz, Tar, Zip };

  explicit ArchiveBuilder(Format format) : a_(archive_write_new()) {
    if (format == Format::Zip) {
      archive_write_set_format_zip(a_);
    } else {
      archive_write_set_format_pax_restricted(a_);
      if (format == Format::TarGz) archive_write_add_filter_gzip(a_);
    }
    archive_write_set_bytes_in_last_block(a_, 1);
    check(archive_write_open(a_, &out_, nullptr, &ArchiveBuilder::append, nullptr), "open");
  }
  ~ArchiveBuilder() { archive_write_free(a_); }
  ArchiveBuilder(const ArchiveBuilder&) = delete;
  ArchiveBuilder& operator=(const ArchiveBuilder&) = delete;

  ArchiveBuilder& file(const std::string& name, const std::string& data) {
    Entry e(name, AE_IFREG, 0644);
    archive_entry_set_size(e.get(), la_int64_t(data.size()));
    check(archive_write_header(a_, e.get()), name);
    if (!data.empty() && archive_write_data(a_, data.data(), data.size()) != la_ssize_t(data.size()))
      throw std::runtime_error("archive_write_data failed for " + name);
    return *this;
  }
  ArchiveBuilder& dir(const std::string& name) { return bare(name, AE_IFDIR, 0755); }
  ArchiveBuilder& fifo(const std::string& name) { return bare(name, AE_IFIFO, 0644); }
  ArchiveBuilder& char_device(const std::string& name) {
    Entry e(name, AE_IFCHR, 0644);
    archive_entry_set_rdev(e.get(), 0x0103);  // like /dev/null
    check(archive_write_header(a_, e.get()), name);
    return *this;
  }
  ArchiveBuilder& symlink(const std::string& name, const std::string& target) {
    Entry e(name, AE_IFLNK, 0777);
    archive_entry_set_symlink(e.get(), target.c_str());
    check(archive_write_header(a_, e.get()), name);
    return *this;
  }
  ArchiveBuilder& hardlink(const std::string& name, const std::string& target) {
    Entry e(name, AE_IFREG, 0644);
    archive_entry_set_hardlink(e.get(), target.c_str());
    check(archive_write_header(a_, e.get()), name);
    return *this;
  }

  std::string finish() {
    check(archive_write_close(a_), "close");
    return out_;
  }

 private:
  struct Entry {
    Entry(const std::string& name, mode_t type, int perm) : e_(archive_entry_new()) {
      archive_entry_set_pathname(e_, name.c_str());
      archive_entry_set_filetype(e_, type);
      archive_entry_set_perm(e_, perm);
      archive_entry_set_mtime(e_, 1700000000, 0);
    }
    ~Entry() { archive_entry_free(e_); }
    archive_entry* get() const { return e_; }
    archive_entry* e_;
  };

  ArchiveBuilder& bare(const std::string& name, mode_t type, int perm) {
    Entry e(name, type, perm);
    check(archive_write_header(a_, e.get()), name);
    return *this;
  }
  void check(int rc, const std::string& what) {
    if (rc < ARCHIVE_WARN) {
      const char* msg = archive_error_string(a_);
      throw std::runtime_error("libarchive (" + what + "): " + (msg ? msg : "?"));
    }
  }
  static la_ssize_t append(archive*, void* client, const void* data, size_t size) {
    static_cast<std::string*>(client)->append(static_cast<const char*>(data), size);
    return la_ssize_t(size);
  }

  archive* a_;
  std::string out_;
};

/// Bytes that do not compress (so cutting an archive in half cuts file data, not padding).
inline std::string noise(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::string s(n, '\0');
  for (char& c : s) c = char(rng() & 0xFF);
  return s;
}

}  // namespace tessera::test
