// Making scene bundles: which files a scene needs, where their common root is, and packing them
// as a tar.gz; plus finding the scene XML inside a received bundle.
//
// Packing is deterministic (fixed mtime, owner and mode; no gzip timestamp), so the same files
// give the same bytes and hence the same SHA-256: the coordinator stores a re-submitted scene once.
#include "tessera/farm/bundle.h"

#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <archive.h>
#include <archive_entry.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace tessera {

namespace {

namespace fs = std::filesystem;

struct WriteFree {
  void operator()(archive* a) const { archive_write_free(a); }
};
struct EntryFree {
  void operator()(archive_entry* e) const { archive_entry_free(e); }
};

la_ssize_t append_to_string(archive*, void* client, const void* data, size_t size) {
  static_cast<std::string*>(client)->append(static_cast<const char*>(data), size);
  return la_ssize_t(size);
}

std::string libarchive_message(archive* a) {
  const char* s = archive_error_string(a);
  return s ? s : "unknown libarchive error";
}

bool ends_with_xml(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".xml";
}

/// Absolute and lexically normal, symlinks kept (see plan_bundle).
fs::path normal_absolute(const std::string& path) { return fs::absolute(fs::path(path)).lexically_normal(); }

fs::path common_dir(const fs::path& a, const fs::path& b) {
  fs::path out;
  for (auto ia = a.begin(), ib = b.begin(); ia != a.end() && ib != b.end() && *ia == *ib; ++ia, ++ib) out /= *ia;
  return out;
}

}  // namespace

std::string pack_bundle(const std::string& root_dir, const std::vector<std::string>& files) {
  std::string out;
  std::unique_ptr<archive, WriteFree> holder(archive_write_new());
  archive* a = holder.get();
  if (!a) throw std::bad_alloc();
  if (archive_write_set_format_pax_restricted(a) != ARCHIVE_OK || archive_write_add_filter_gzip(a) != ARCHIVE_OK)
    throw std::runtime_error("libarchive cannot write tar.gz: " + libarchive_message(a));
  // Without this the gzip header carries the current time and equal bundles hash differently.
  (void)archive_write_set_filter_option(a, "gzip", "timestamp", nullptr);
  (void)archive_write_set_bytes_in_last_block(a, 1);
  if (archive_write_open(a, &out, nullptr, append_to_string, nullptr) != ARCHIVE_OK)
    throw std::runtime_error("libarchive cannot start a bundle: " + libarchive_message(a));

  std::vector<char> buf(size_t(1) << 20);
  for (const std::string& rel : files) {
    fs::path rel_path(rel);
    if (rel.empty() || rel_path.is_absolute() || rel.find('\\') != std::string::npos ||
        std::find(rel_path.begin(), rel_path.end(), fs::path("..")) != rel_path.end())
      throw std::runtime_error("cannot pack '" + rel + "': bundle paths must be relative, '/'-separated, without '..'");
    const fs::path full = fs::path(root_dir) / rel_path;
    std::error_code ec;
    if (!fs::is_regular_file(full, ec))
      throw std::runtime_error("cannot pack '" + full.string() + "': not a readable regular file");
    const uintmax_t size = fs::file_size(full, ec);
    std::ifstream in(full, std::ios::binary);
    if (ec || !in) throw std::runtime_error("cannot read '" + full.string() + "' to pack it");

    std::unique_ptr<archive_entry, EntryFree> e(archive_entry_new());
    // Raw bytes (UTF-8 on our platforms): the _utf8 setter crashes libarchive 3.6's pax writer in
    // the C locale.
    archive_entry_set_pathname(e.get(), rel_path.lexically_normal().generic_string().c_str());
    archive_entry_set_filetype(e.get(), AE_IFREG);
    archive_entry_set_perm(e.get(), 0644);
    archive_entry_set_size(e.get(), la_int64_t(size));
    archive_entry_set_mtime(e.get(), 0, 0);
    if (archive_write_header(a, e.get()) < ARCHIVE_WARN)
      throw std::runtime_error("cannot pack '" + rel + "': " + libarchive_message(a));
    uintmax_t written = 0;
    while (in) {
      in.read(buf.data(), std::streamsize(buf.size()));
      const size_t n = size_t(in.gcount());
      if (n == 0) break;
      if (written + n > size) throw std::runtime_error("'" + full.string() + "' grew while being packed");
      if (archive_write_data(a, buf.data(), n) != la_ssize_t(n))
        throw std::runtime_error("cannot pack '" + rel + "': " + libarchive_message(a));
      written += n;
    }
    if (in.bad() || written != size)
      throw std::runtime_error("error while reading '" + full.string() + "' to pack it");
  }
  if (archive_write_close(a) != ARCHIVE_OK)
    throw std::runtime_error("cannot finish the bundle: " + libarchive_message(a));
  return out;
}

BundlePlan plan_bundle(const std::string& scene_xml, const std::vector<std::string>& referenced) {
  // Lexical normalisation rather than canonical paths: a scene's names are resolved as strings
  // against its folder ("textures/x.png" under a symlinked `textures`), so the bundle must keep the
  // layout as the scene spells it, not where symlinks point.
  const fs::path xml = normal_absolute(scene_xml);
  std::vector<fs::path> others;
  fs::path root = xml.parent_path();
  for (const std::string& r : referenced) {
    if (r.empty()) continue;
    fs::path p = normal_absolute(r);
    root = common_dir(root, p.parent_path());
    others.push_back(std::move(p));
  }
  BundlePlan plan;
  plan.root_dir = root.string();
  const std::string xml_rel = xml.lexically_relative(root).generic_string();
  plan.files.push_back(xml_rel);
  std::set<std::string> rest;
  for (const fs::path& p : others) rest.insert(p.lexically_relative(root).generic_string());
  rest.erase(xml_rel);
  plan.files.insert(plan.files.end(), rest.begin(), rest.end());
  return plan;
}

std::string find_scene_xml(const std::vector<BundleEntry>& files, const std::string& requested,
                           std::string& error) {
  error.clear();
  if (!requested.empty()) {
    if (!ends_with_xml(requested)) {
      error = "scene '" + requested + "' is not an .xml file";
      return "";
    }
    for (const BundleEntry& f : files)
      if (f.path == requested) return f.path;
    error = "scene '" + requested + "' is not in the bundle";
    return "";
  }
  std::vector<std::string> at_root, deeper;
  for (const BundleEntry& f : files)
    if (ends_with_xml(f.path)) (f.path.find('/') == std::string::npos ? at_root : deeper).push_back(f.path);
  if (at_root.size() == 1) return at_root[0];
  auto join = [](const std::vector<std::string>& names) {
    std::string s;
    for (size_t i = 0; i < names.size() && i < 10; ++i) s += (i ? ", '" : "'") + names[i] + "'";
    return names.size() > 10 ? s + ", ..." : s;
  };
  if (at_root.empty()) {
    error = "no .xml file at the bundle's root";
    if (!deeper.empty()) error += " (found " + join(deeper) + ": name the scene file)";
  } else {
    error = "several .xml files at the bundle's root (" + join(at_root) + "): name the scene file";
  }
  return "";
}

std::vector<std::string> scene_files(const SceneDesc& desc, const LoadResult& loaded) {
  std::vector<std::string> out;
  std::set<std::string> seen;
  auto add = [&](const std::string& f) {
    if (!f.empty() && seen.insert(f).second) out.push_back(f);
  };
  add(desc.file);
  for (const std::string& f : desc.included_files) add(f);
  for (const std::string& f : desc.spectrum_files) add(f);
  for (const std::string& f : loaded.files) add(f);
  return out;
}

}  // namespace tessera
