// Reading scene bundles: the one walk over an archive that inspect and unpack share
// (bundle_walk.h), so the same checks guard both; unpacking only adds a sink that writes files.
//
// Sizes are checked twice: against the headers (a bomb is refused before it is inflated) and
// against the bytes actually produced (a header that lies cannot get past the limit).
#include "tessera/farm/bundle.h"

#include "bundle_walk.h"

#include <archive.h>
#include <archive_entry.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <memory>
#include <set>
#include <stdexcept>
#include <vector>

namespace tessera {

namespace {

struct ReadFree {
  void operator()(archive* a) const { archive_read_free(a); }
};

std::string entry_error(const std::string& name, const std::string& what) {
  return "bundle entry '" + name + "': " + what;
}

std::string libarchive_message(archive* a) {
  const char* s = archive_error_string(a);
  return s ? s : "unexpected end of data";  // libarchive sets no message for some truncations
}

/// Normalises an archive path into `out` ("a/./b//c" -> "a/b/c"); returns what is wrong, or "".
std::string normalise_path(const std::string& raw, bool is_dir, std::string& out) {
  out.clear();
  if (raw.empty()) return "empty name";
  // Linux's PATH_MAX; also keeps folder creation from recursing through absurdly deep paths.
  if (raw.size() > 4096) return "path longer than 4096 bytes";
  for (char c : raw)
    if (static_cast<unsigned char>(c) < 0x20) return "control character in path";
  if (raw.find('\\') != std::string::npos) return "backslash in path (bundle paths use '/')";
  if (raw.front() == '/') return "absolute path";
  if (raw.size() >= 2 && raw[1] == ':' && std::isalpha(static_cast<unsigned char>(raw[0])))
    return "absolute path (drive letter)";
  size_t start = 0;
  while (start <= raw.size()) {
    size_t end = raw.find('/', start);
    if (end == std::string::npos) end = raw.size();
    std::string part = raw.substr(start, end - start);
    if (part == "..") return "path leaves the bundle";
    if (!part.empty() && part != ".") out += (out.empty() ? "" : "/") + part;
    start = end + 1;
  }
  if (out.empty() && !is_dir) return "empty name";
  return "";
}

/// Inflates the whole gzip stream once more, discarding the output, to check what libarchive does
/// not: the tar reader stops at the tar end marker and never reaches the gzip trailer, so a CRC or
/// length mismatch (a corrupted upload) would pass. `cap` bounds the work (anything hidden after
/// the tar end marker). Returns what is wrong, or "".
std::string verify_gzip(std::string_view bytes, uint64_t cap) {
  z_stream zs{};
  if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK) return "zlib cannot start";
  std::vector<unsigned char> out(size_t(256) << 10);
  const unsigned char* data = reinterpret_cast<const unsigned char*>(bytes.data());
  size_t fed = 0;  // zlib takes at most 4 GiB of input per call
  auto refill = [&] {
    if (zs.avail_in != 0 || fed == bytes.size()) return;
    const size_t n = std::min(bytes.size() - fed, size_t(1) << 30);
    zs.next_in = const_cast<Bytef*>(data + fed);
    zs.avail_in = uInt(n);
    fed += n;
  };
  uint64_t produced = 0;
  std::string error;
  for (;;) {
    refill();
    zs.next_out = out.data();
    zs.avail_out = uInt(out.size());
    int rc = inflate(&zs, Z_NO_FLUSH);
    produced += out.size() - zs.avail_out;
    if (produced > cap) {
      error = "compressed stream holds more than its entries (corrupt bundle)";
      break;
    }
    if (rc == Z_STREAM_END) {
      // Another gzip member may follow (concatenated .gz files); anything else but zero padding is junk.
      const unsigned char* rest = zs.next_in;
      size_t left = zs.avail_in + (bytes.size() - fed);  // contiguous: next_in points into `bytes`
      if (left >= 2 && rest[0] == 0x1f && rest[1] == 0x8b) {
        inflateReset(&zs);
        continue;
      }
      for (size_t i = 0; i < left && error.empty(); ++i)
        if (rest[i] != 0) error = "unexpected data after the compressed stream (corrupt bundle)";
      break;
    }
    if (rc != Z_OK) {
      error = std::string("corrupt compressed data (") + (zs.msg ? zs.msg : "truncated") + ")";
      break;
    }
    if (zs.avail_in == 0 && zs.avail_out != 0) {
      error = "truncated compressed data";
      break;
    }
  }
  inflateEnd(&zs);
  return error;
}

/// Why a bundle of `bundle_bytes` may not unpack past `limits.unpacked_limit(bundle_bytes)`,
/// naming the tessera-server flag that sets the limit in force.
std::string unpacked_limit_text(const BundleLimits& limits, uint64_t bundle_bytes) {
  const uint64_t limit = limits.unpacked_limit(bundle_bytes);
  if (limit < limits.max_unpacked_bytes) {
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, "%g", limits.max_ratio);
    return "unpacked size exceeds " + std::to_string(limit) + " bytes, the compression-ratio limit for a bundle of " +
           std::to_string(bundle_bytes) + " bytes (" + std::to_string(limits.ratio_floor_bytes) + " + " + ratio +
           " x its size; --max-ratio): a decompression bomb, or a scene that needs a higher --max-ratio";
  }
  return "unpacked size exceeds the limit of " + std::to_string(limits.max_unpacked_bytes) + " bytes (--max-unpacked)";
}

}  // namespace

uint64_t BundleLimits::unpacked_limit(uint64_t bundle_bytes) const {
  if (!(max_ratio > 0)) return max_unpacked_bytes;
  // In floating point: max_ratio x a 4 GiB bundle may not fit in 64 bits.
  const double by_ratio = double(ratio_floor_bytes) + max_ratio * double(bundle_bytes);
  return by_ratio >= double(max_unpacked_bytes) ? max_unpacked_bytes : uint64_t(by_ratio);
}

namespace detail {

BundleResult walk_bundle(std::string_view bytes, const BundleLimits& limits, EntrySink* sink) {
  BundleResult r;
  if (bytes.empty()) {
    r.error = "empty bundle (0 bytes)";
    return r;
  }
  std::unique_ptr<archive, ReadFree> holder(archive_read_new());
  archive* a = holder.get();
  if (!a) throw std::bad_alloc();
  // gzip only, not filter_all: that would also hand network input to external programs (lrzip,
  // lzop, grzip), and every filter's trailer check would need the treatment verify_gzip gives gzip.
  archive_read_support_filter_gzip(a);
  archive_read_support_format_tar(a);
  archive_read_support_format_zip(a);
  // A truncated gzip already fails in open (libarchive reads ahead): tell it from a wrong format.
  const bool magic = bytes.compare(0, 2, "\x1f\x8b") == 0 || bytes.compare(0, 2, "PK") == 0 ||
                     (bytes.size() > 262 && bytes.compare(257, 5, "ustar") == 0);
  auto unreadable = [&](bool recognised) {
    return (recognised ? "corrupt or truncated bundle (" : "not a .tar.gz, .tar or .zip bundle (") +
           libarchive_message(a) + ")";
  };
  if (archive_read_open_memory(a, bytes.data(), bytes.size()) != ARCHIVE_OK) {
    r.error = unreadable(magic);
    return r;
  }

  std::set<std::string> files, dirs;
  uint64_t entries = 0, declared_bytes = 0, actual_bytes = 0;
  std::string last = "";
  std::vector<char> buf(size_t(64) << 10);
  const uint64_t max_unpacked = limits.unpacked_limit(bytes.size());
  const std::string limit_text = unpacked_limit_text(limits, bytes.size());
  for (;;) {
    archive_entry* e = nullptr;
    int rc = archive_read_next_header(a, &e);
    if (rc == ARCHIVE_EOF) break;
    if (rc < ARCHIVE_WARN) {
      if (entries == 0)
        r.error = unreadable(magic || archive_format(a) != 0 || archive_filter_code(a, 0) > ARCHIVE_FILTER_NONE);
      else
        r.error = "corrupt or truncated bundle after entry '" + last + "' (" + libarchive_message(a) + ")";
      return r;
    }
    if (++entries > limits.max_files) {
      r.error = "bundle has more than " + std::to_string(limits.max_files) + " entries";
      return r;
    }
    const char* raw_c = archive_entry_pathname_utf8(e);
    if (!raw_c) raw_c = archive_entry_pathname(e);
    const std::string raw = raw_c ? raw_c : "";
    std::string shown = raw;  // for messages: control characters would garble them
    for (char& c : shown)
      if (static_cast<unsigned char>(c) < 0x20) c = '?';
    if (shown.empty()) shown.append("#").append(std::to_string(entries));  // (GCC 12 -Wrestrict on "#" + ...)
    last = shown;

    const mode_t type = archive_entry_filetype(e);
    if (archive_entry_hardlink(e)) {
      r.error = entry_error(shown, "hard link (bundles hold regular files and folders only)");
      return r;
    }
    if (type == AE_IFLNK || archive_entry_symlink(e)) {
      r.error = entry_error(shown, "symbolic link (bundles hold regular files and folders only)");
      return r;
    }
    if (type != AE_IFREG && type != AE_IFDIR) {
      r.error = entry_error(shown, "device, fifo or socket (bundles hold regular files and folders only)");
      return r;
    }
    const bool is_dir = type == AE_IFDIR;
    std::string path;
    if (std::string what = normalise_path(raw, is_dir, path); !what.empty()) {
      r.error = entry_error(shown, what);
      return r;
    }

    // Parents of every entry are folders; a path may not be both, nor a file twice.
    for (size_t slash = path.find('/'); slash != std::string::npos; slash = path.find('/', slash + 1)) {
      std::string parent = path.substr(0, slash);
      if (files.count(parent)) {
        r.error = entry_error(shown, "path runs through file '" + parent + "'");
        return r;
      }
      dirs.insert(parent);
    }
    if (is_dir) {
      if (files.count(path)) {
        r.error = entry_error(shown, "folder has the same path as a file");
        return r;
      }
      if (!path.empty()) dirs.insert(path);
      if (sink && !path.empty())
        if (std::string err = sink->directory(path); !err.empty()) {
          r.error = entry_error(shown, err);
          return r;
        }
      continue;
    }
    if (files.count(path) || dirs.count(path)) {
      r.error = entry_error(shown, "duplicate path");
      return r;
    }
    files.insert(path);

    const bool size_known = archive_entry_size_is_set(e);
    const int64_t declared = size_known ? archive_entry_size(e) : 0;
    if (declared < 0) {
      r.error = entry_error(shown, "negative size in header (corrupt bundle)");
      return r;
    }
    if (uint64_t(declared) > max_unpacked - declared_bytes) {
      r.error = entry_error(shown, limit_text);
      return r;
    }
    declared_bytes += uint64_t(declared);

    if (sink)
      if (std::string err = sink->begin(path); !err.empty()) {
        r.error = entry_error(shown, err);
        return r;
      }
    uint64_t got = 0;
    for (;;) {
      la_ssize_t n = archive_read_data(a, buf.data(), buf.size());
      if (n < 0) {
        r.error = entry_error(shown, "corrupt or truncated data (" + libarchive_message(a) + ")");
        return r;
      }
      if (n == 0) break;
      got += uint64_t(n);
      if (uint64_t(n) > max_unpacked - actual_bytes) {
        r.error = entry_error(shown, limit_text);
        return r;
      }
      actual_bytes += uint64_t(n);
      if (size_known && got > uint64_t(declared)) {
        r.error = entry_error(shown, "holds more data than its header says (corrupt bundle)");
        return r;
      }
      if (sink)
        if (std::string err = sink->write(buf.data(), size_t(n)); !err.empty()) {
          r.error = entry_error(shown, err);
          return r;
        }
    }
    if (size_known && got != uint64_t(declared)) {
      r.error = entry_error(shown, "truncated data (" + std::to_string(got) + " of " +
                                       std::to_string(declared) + " bytes)");
      return r;
    }
    if (sink)
      if (std::string err = sink->end(); !err.empty()) {
        r.error = entry_error(shown, err);
        return r;
      }
    r.files.push_back({path, got});
  }
  if (bytes.size() >= 2 && uint8_t(bytes[0]) == 0x1f && uint8_t(bytes[1]) == 0x8b)
    if (std::string err = verify_gzip(bytes, actual_bytes + entries * (uint64_t(64) << 10) + (uint64_t(1) << 20));
        !err.empty()) {
      r.error = err;
      return r;
    }
  return r;
}

}  // namespace detail

BundleResult inspect_bundle(std::string_view bytes, const BundleLimits& limits) {
  return detail::walk_bundle(bytes, limits, nullptr);
}

}  // namespace tessera
