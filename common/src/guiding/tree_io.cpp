#include "tessera/guiding/tree_io.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <vector>

namespace tessera {

static_assert(std::endian::native == std::endian::little, "trees are written little-endian");

namespace {

constexpr char kTreeMagic[4] = {'T', 'S', 'D', 'T'};
constexpr char kRecordsMagic[4] = {'T', 'S', 'D', 'R'};
// Version 2 added each leaf's pixel statistics and estimates, version 3 the guide's gain (trees:
// its sums, prediction, iteration and the one it stepped aside at; records: their sums). Older versions are
// still read, as zeros.
constexpr uint32_t kVersion = 3;

struct Writer {
  std::string& out;
  template <class T>
  void put(const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void varint(uint64_t v) {
    for (; v >= 0x80; v >>= 7) out.push_back(char(uint8_t(v) | 0x80));
    out.push_back(char(v));
  }
  void signed_varint(int64_t v) { varint((uint64_t(v) << 1) ^ uint64_t(v >> 63)); }
};

// Reads until the bytes run out; then every value is 0 and ok is false.
struct Reader {
  std::string_view in;
  size_t pos = 0;
  bool ok = true;
  uint32_t version = 0;
  template <class T>
  T get() {
    T v{};
    if (in.size() - pos < sizeof(T)) {
      ok = false;
      return v;
    }
    std::memcpy(&v, in.data() + pos, sizeof(T));
    pos += sizeof(T);
    return v;
  }
  uint64_t varint() {
    uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (pos >= in.size()) break;
      const uint8_t b = uint8_t(in[pos++]);
      v |= uint64_t(b & 0x7f) << shift;
      if (!(b & 0x80)) return v;
    }
    ok = false;
    return 0;
  }
  int64_t signed_varint() {
    const uint64_t v = varint();
    return int64_t(v >> 1) ^ -int64_t(v & 1);
  }
  bool magic(const char (&m)[4]) {
    if (in.size() < 8 || std::memcmp(in.data(), m, 4) != 0) return false;
    pos = 4;
    version = get<uint32_t>();
    return version >= 1 && version <= kVersion;
  }
  size_t left() const { return in.size() - pos; }
};

}  // namespace

struct TreeIo {
  static void write(Writer& w, const DirectionalTree& t) {
    w.put(uint32_t(t.nodes_.size()));
    for (const DirectionalTree::Node& n : t.nodes_) {
      for (uint32_t c : n.child) w.put(c);
      for (uint64_t s : n.sum) w.put(s);
    }
  }
  // Children come after their parent (as refined() makes them), so traversal always ends.
  static bool read(Reader& r, DirectionalTree& t) {
    const uint32_t count = r.get<uint32_t>();
    if (!r.ok || count == 0 || count > r.left() / sizeof(DirectionalTree::Node)) return false;
    t.nodes_.resize(count);
    for (uint32_t i = 0; i < count; ++i) {
      DirectionalTree::Node& n = t.nodes_[i];
      for (uint32_t& c : n.child)
        if (c = r.get<uint32_t>(); c != 0 && (c <= i || c >= count)) return false;
      for (uint64_t& s : n.sum) s = r.get<uint64_t>();
    }
    t.set_cells();
    return r.ok && t.depth() <= DirectionalTree::kMaxDepth;  // (as refined() makes them)
  }
  static void write(Writer& w, const BsdfFractionLoss& l) {
    for (int64_t v : l.loss_) w.put(v);
    w.put(l.records_);
  }
  static void read(Reader& r, BsdfFractionLoss& l) {
    for (int64_t& v : l.loss_) v = r.get<int64_t>();
    l.records_ = r.get<uint64_t>();
  }

  static std::string write_tree(const SpatialTree& t) {
    std::string out;
    Writer w{out};
    out.append(kTreeMagic, 4);
    w.put(kVersion);
    for (float v : {t.bounds_.lo.x, t.bounds_.lo.y, t.bounds_.lo.z, t.bounds_.hi.x, t.bounds_.hi.y, t.bounds_.hi.z}) w.put(v);
    w.put(uint32_t(t.nodes_.size()));
    for (const SpatialTree::Node& n : t.nodes_) {
      w.put(n.child[0]);
      w.put(n.child[1]);
      w.put(n.leaf);
    }
    w.put(uint32_t(t.leaves_.size()));
    for (const SpatialTree::Leaf& l : t.leaves_) {
      w.put(l.samples);
      w.put(l.pixel_sum);
      w.put(l.pixel_paths);
      w.put(l.bsdf_fraction);
      w.put(l.radiance);
      w.put(l.pixel);
      write(w, l.fraction_loss);
      write(w, l.sampling);
      write(w, l.building);
    }
    w.put(t.gain_.plain);
    w.put(t.gain_.guided);
    w.put(t.gain_.paths);
    w.put(t.predicted_gain_);
    w.put(t.iteration_);
    w.put(t.aside_from_);
    return out;
  }

  static bool read_nodes(Reader& r, SpatialTree& t) {
    const uint32_t count = r.get<uint32_t>();
    if (!r.ok || count == 0 || count > r.left() / 12) return false;
    t.nodes_.resize(count);
    std::vector<bool> has_parent(count, false);  // (a tree: no node is reached twice)
    for (uint32_t i = 0; i < count; ++i) {
      SpatialTree::Node& n = t.nodes_[i];
      n.child[0] = r.get<uint32_t>();
      n.child[1] = r.get<uint32_t>();
      n.leaf = r.get<uint32_t>();
      if (n.leaf == SpatialTree::kNoLeaf)
        for (uint32_t c : n.child) {
          if (c <= i || c >= count || has_parent[c]) return false;
          has_parent[c] = true;
        }
    }
    return r.ok;
  }

  static bool read_tree(std::string_view bytes, SpatialTree& t, std::string& error) {
    Reader r{bytes};
    SpatialTree out;
    bool ok = r.magic(kTreeMagic);
    float b[6];
    for (float& v : b) v = r.get<float>();
    out.bounds_.lo = Vec3(b[0], b[1], b[2]);
    out.bounds_.hi = Vec3(b[3], b[4], b[5]);
    ok = ok && std::all_of(b, b + 6, [](float v) { return std::isfinite(v); }) && !out.bounds_.empty();
    ok = ok && read_nodes(r, out);
    const uint32_t leaves = ok ? r.get<uint32_t>() : 0;
    ok = ok && r.ok && leaves > 0 && leaves <= r.left() / 8;
    if (ok) out.leaves_.resize(leaves);
    for (uint32_t i = 0; ok && i < leaves; ++i) {
      SpatialTree::Leaf& l = out.leaves_[i];
      l.samples = r.get<uint64_t>();
      if (r.version > 1) l.pixel_sum = r.get<uint64_t>(), l.pixel_paths = r.get<uint64_t>();
      l.bsdf_fraction = r.get<float>();
      if (r.version > 1) l.radiance = r.get<float>(), l.pixel = r.get<float>();
      read(r, l.fraction_loss);
      // (Estimates are finite and not negative: roulette divides by them.)
      ok = l.bsdf_fraction >= 0.f && l.bsdf_fraction <= 1.f && l.radiance >= 0.f && l.pixel >= 0.f &&
           std::isfinite(l.radiance) && std::isfinite(l.pixel) && read(r, l.sampling) && read(r, l.building);
    }
    for (const SpatialTree::Node& n : out.nodes_) ok = ok && (n.leaf == SpatialTree::kNoLeaf || n.leaf < leaves);
    if (ok && r.version > 2) {
      out.gain_.plain = r.get<uint64_t>();
      out.gain_.guided = r.get<uint64_t>();
      out.gain_.paths = r.get<uint64_t>();
      out.predicted_gain_ = r.get<float>();
      out.iteration_ = r.get<uint32_t>();
      out.aside_from_ = r.get<uint32_t>();
      ok = out.predicted_gain_ >= 0.f && std::isfinite(out.predicted_gain_) && out.aside_from_ <= out.iteration_;
    }
    if (!ok || !r.ok || r.left() != 0) {
      error = "guide: not a well-formed SD-tree";
      return false;
    }
    out.index_nodes();
    out.update_gain_scale();
    t = std::move(out);
    return true;
  }

  static SpatialTree recorder(const SpatialTree& t) {
    SpatialTree out;
    out.bounds_ = t.bounds_;
    out.nodes_ = t.nodes_;
    out.steps_ = t.steps_;
    out.leaves_.resize(t.leaves_.size());
    for (size_t i = 0; i < t.leaves_.size(); ++i) out.leaves_[i].building = t.leaves_[i].building.cleared();
    return out;
  }

  // Each leaf's building sums, flattened (node * 4 + quadrant), start at offsets[leaf].
  static std::vector<uint64_t> offsets(const SpatialTree& t) {
    std::vector<uint64_t> out(t.leaves_.size() + 1, 0);
    for (size_t i = 0; i < t.leaves_.size(); ++i) out[i + 1] = out[i] + 4 * uint64_t(t.leaves_[i].building.nodes_.size());
    return out;
  }

  static std::string write_records(const SpatialTree& t) {
    std::string out;
    Writer w{out};
    out.append(kRecordsMagic, 4);
    w.put(kVersion);
    const std::vector<uint64_t> offset = offsets(t);
    w.put(uint32_t(t.leaves_.size()));
    w.put(offset.back());
    std::vector<uint32_t> counted, lossy;
    for (uint32_t i = 0; i < t.leaves_.size(); ++i) {
      if (t.leaves_[i].samples) counted.push_back(i);
      if (!(t.leaves_[i].fraction_loss == BsdfFractionLoss{})) lossy.push_back(i);
    }
    w.varint(counted.size());
    for (size_t k = 0; k < counted.size(); ++k) {
      w.varint(counted[k] - (k ? counted[k - 1] : 0));
      w.varint(t.leaves_[counted[k]].samples);
    }
    w.varint(lossy.size());
    for (size_t k = 0; k < lossy.size(); ++k) {
      w.varint(lossy[k] - (k ? lossy[k - 1] : 0));
      for (int64_t v : t.leaves_[lossy[k]].fraction_loss.loss_) w.signed_varint(v);
      w.varint(t.leaves_[lossy[k]].fraction_loss.records_);
    }
    std::vector<uint32_t> pixels;
    for (uint32_t i = 0; i < t.leaves_.size(); ++i)
      if (t.leaves_[i].pixel_paths) pixels.push_back(i);
    w.varint(pixels.size());
    for (size_t k = 0; k < pixels.size(); ++k) {
      w.varint(pixels[k] - (k ? pixels[k - 1] : 0));
      w.varint(t.leaves_[pixels[k]].pixel_paths);
      w.varint(t.leaves_[pixels[k]].pixel_sum);
    }
    w.varint(t.gain_.plain);
    w.varint(t.gain_.guided);
    w.varint(t.gain_.paths);
    std::vector<std::pair<uint64_t, uint64_t>> sums;
    for (uint32_t i = 0; i < t.leaves_.size(); ++i) {
      const std::vector<DirectionalTree::Node>& nodes = t.leaves_[i].building.nodes_;
      for (size_t n = 0; n < nodes.size(); ++n)
        for (int q = 0; q < 4; ++q)
          if (nodes[n].sum[q] != 0) sums.emplace_back(offset[i] + 4 * n + uint64_t(q), nodes[n].sum[q]);
    }
    w.varint(sums.size());
    for (size_t k = 0; k < sums.size(); ++k) {
      w.varint(sums[k].first - (k ? sums[k - 1].first : 0));
      w.varint(sums[k].second);
    }
    return out;
  }

  struct Records {
    std::vector<std::pair<uint32_t, uint64_t>> samples;
    std::vector<std::pair<uint32_t, BsdfFractionLoss>> losses;
    struct Pixel {
      uint32_t leaf;
      uint64_t paths, sum;
    };
    std::vector<Pixel> pixels;
    GuideGain gain;
    struct Sum {
      uint32_t leaf;
      uint64_t cell;  // node * 4 + quadrant in the leaf's building tree
      uint64_t value;
    };
    std::vector<Sum> sums;
  };
  static bool parse_records(const SpatialTree& t, std::string_view bytes, Records& out, std::string& error);
  static bool add_records(SpatialTree& t, std::string_view bytes, std::string& error);
};

// Parses and checks everything against the tree's cells, without changing it.
bool TreeIo::parse_records(const SpatialTree& t, std::string_view bytes, Records& out, std::string& error) {
  const std::vector<uint64_t> offset = offsets(t);
  Reader r{bytes};
  bool ok = r.magic(kRecordsMagic) && r.get<uint32_t>() == t.leaves_.size() && r.get<uint64_t>() == offset.back();
  // Each list's entries: a leaf (or flat index) as the step from the previous one, then values.
  auto read_list = [&](uint64_t limit, auto&& read_entry) {
    const uint64_t count = ok ? r.varint() : 0;
    ok = ok && r.ok && count <= r.left();
    for (uint64_t k = 0, at = 0; ok && k < count; ++k) {
      at += r.varint();
      ok = r.ok && at < limit;
      if (ok) read_entry(at);
    }
  };
  read_list(t.leaves_.size(), [&](uint64_t leaf) { out.samples.emplace_back(uint32_t(leaf), r.varint()); });
  read_list(t.leaves_.size(), [&](uint64_t leaf) {
    BsdfFractionLoss l;
    for (int64_t& v : l.loss_) v = r.signed_varint();
    l.records_ = r.varint();
    out.losses.emplace_back(uint32_t(leaf), l);
  });
  if (r.version > 1)
    read_list(t.leaves_.size(), [&](uint64_t leaf) {
      const uint64_t paths = r.varint();
      out.pixels.push_back({uint32_t(leaf), paths, r.varint()});
    });
  if (ok && r.version > 2) {
    out.gain.plain = r.varint();
    out.gain.guided = r.varint();
    out.gain.paths = r.varint();
  }
  read_list(offset.back(), [&](uint64_t at) {
    // Only leaf quadrants hold recorded sums (inner ones are made by build()).
    const size_t leaf = size_t(std::upper_bound(offset.begin(), offset.end(), at) - offset.begin()) - 1;
    const uint64_t cell = at - offset[leaf];
    ok = t.leaves_[leaf].building.nodes_[cell / 4].child[cell % 4] == 0;
    out.sums.push_back({uint32_t(leaf), cell, r.varint()});
  });
  if (!ok || !r.ok || r.left() != 0) {
    error = "training records: malformed, or not recorded with this job's guide";
    return false;
  }
  return true;
}

bool TreeIo::add_records(SpatialTree& t, std::string_view bytes, std::string& error) {
  Records records;
  if (!parse_records(t, bytes, records, error)) return false;  // (the tree unchanged)
  for (auto& [leaf, n] : records.samples) t.leaves_[leaf].samples += n;
  for (auto& [leaf, l] : records.losses) t.leaves_[leaf].fraction_loss.merge(l);
  for (const Records::Pixel& p : records.pixels) {
    t.leaves_[p.leaf].pixel_paths += p.paths;
    t.leaves_[p.leaf].pixel_sum += p.sum;
  }
  t.gain_.merge(records.gain);
  for (const Records::Sum& s : records.sums)  // (wraps as record()'s atomic add does)
    t.leaves_[s.leaf].building.nodes_[s.cell / 4].sum[s.cell % 4] += s.value;
  return true;
}

std::string write_tree(const SpatialTree& tree) { return TreeIo::write_tree(tree); }
bool read_tree(std::string_view bytes, SpatialTree& out, std::string& error) { return TreeIo::read_tree(bytes, out, error); }
SpatialTree make_recorder(const SpatialTree& tree) { return TreeIo::recorder(tree); }
std::string write_records(const SpatialTree& recorder) { return TreeIo::write_records(recorder); }
bool add_records(SpatialTree& tree, std::string_view records, std::string& error) {
  return TreeIo::add_records(tree, records, error);
}
bool check_records(const SpatialTree& tree, std::string_view records, std::string& error) {
  TreeIo::Records parsed;
  return TreeIo::parse_records(tree, records, parsed, error);
}

}  // namespace tessera
