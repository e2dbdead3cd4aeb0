// Fuzzing the scene loader with broken versions of the real scenes: truncations, byte flips,
// deletions, duplicated lines, swapped attribute values, hostile numbers, self-includes and deep
// nesting. Parsing must either succeed or throw SceneError; when it succeeds on the small scenes
// (cornell-box, veach-mis) the description is also loaded with --allow-unsupported (and without),
// with the same rule. Anything else -- another exception type, a crash, an ASan report -- fails.
// Run under TESSERA_SANITIZE=ON (label `fuzz`). Deterministic: fixed seed, own RNG.
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace tessera {
namespace {

constexpr int kDefaultIterations = 12000;

/// TESSERA_FUZZ_ITERATIONS / TESSERA_FUZZ_SEED let a longer hunt run locally; CI uses the defaults.
uint64_t env_or(const char* name, uint64_t def) {
  const char* v = std::getenv(name);
  return v && *v ? std::strtoull(v, nullptr, 10) : def;
}

struct Rng {
  uint64_t state;
  uint64_t next() {  // splitmix64
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  size_t below(size_t n) { return n == 0 ? 0 : size_t(next() % n); }
  bool chance(int percent) { return below(100) < size_t(percent); }
};

struct SceneText {
  std::string name, path, text;
  bool load;    // small enough to load every successful parse
  int weight;   // relative frequency
};

const char* const kHostileNumbers[] = {
    "nan", "-nan", "inf", "-inf", "1e38", "3.5e38", "1e39", "-1e300", "1e-45", "1e-320", "0", "-0", "-1",
    "999999999999", "2147483648", "-2147483649", "9223372036854775808", "0x10", "1.0x", "", " ", "1e", ".",
    "-", "+", "1,2", "$", "$undefined", "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17", "#ff00ff", "#zz",
    "400:1, 500:2", "500:1, 400:2", "5000K", "true", "1e-30", "65536", "32769", "-32768"};

const char* const kJunk[] = {"<", ">", "/>", "\"", "'", "=", "&amp;", "&bogus;", "$", "<!--", "-->", "<![CDATA[",
                             "]]>", "<ref id=\"x\"/>", "<include filename=\"scene.xml\"/>", "\xff\xfe", "\0", "\n",
                             "<scene version=\"3.0.0\">", "</scene>", "<transform name=\"to_world\">",
                             "<default name=\"spp\" value=\"1\"/>"};

std::vector<size_t> find_all(const std::string& s, const std::string& needle) {
  std::vector<size_t> out;
  for (size_t p = s.find(needle); p != std::string::npos; p = s.find(needle, p + 1)) out.push_back(p);
  return out;
}

/// The [begin, end) range of the value of the attribute starting at `pos` (pointing at `name="`).
bool value_range(const std::string& s, size_t pos, size_t& begin, size_t& end) {
  begin = s.find('"', pos);
  if (begin == std::string::npos) return false;
  ++begin;
  end = s.find('"', begin);
  return end != std::string::npos;
}

std::string mutate(const std::string& in, Rng& rng, std::string& how) {
  std::string s = in;
  int n = rng.chance(70) ? 1 : 2 + int(rng.below(2));
  for (int k = 0; k < n && !s.empty(); ++k) {
    switch (rng.below(9)) {
      case 0: {  // truncate
        size_t at = rng.below(s.size());
        s.resize(at);
        how += "truncate@" + std::to_string(at) + " ";
        break;
      }
      case 1: {  // byte flips
        int flips = 1 + int(rng.below(8));
        for (int i = 0; i < flips; ++i) s[rng.below(s.size())] = char(rng.below(256));
        how += "flip*" + std::to_string(flips) + " ";
        break;
      }
      case 2: {  // delete a range
        size_t at = rng.below(s.size()), len = 1 + rng.below(64);
        s.erase(at, len);
        how += "erase@" + std::to_string(at) + " ";
        break;
      }
      case 3: {  // duplicate a line somewhere else
        auto lines = find_all(s, "\n");
        if (lines.size() < 2) break;
        size_t i = rng.below(lines.size() - 1);
        std::string line = s.substr(lines[i], lines[i + 1] - lines[i]);
        size_t dst = lines[rng.below(lines.size())];
        s.insert(dst, line);
        how += "dupline ";
        break;
      }
      case 4: {  // swap two attribute values
        auto vals = find_all(s, "value=\"");
        if (vals.size() < 2) break;
        size_t a0, a1, b0, b1;
        size_t ia = rng.below(vals.size()), ib = rng.below(vals.size());
        if (ia == ib) break;
        if (ia > ib) std::swap(ia, ib);
        if (!value_range(s, vals[ia], a0, a1) || !value_range(s, vals[ib], b0, b1) || a1 >= b0) break;
        std::string va = s.substr(a0, a1 - a0), vb = s.substr(b0, b1 - b0);
        s.replace(b0, b1 - b0, va);
        s.replace(a0, a1 - a0, vb);
        how += "swapvalues ";
        break;
      }
      case 5: {  // a hostile number in some attribute value
        auto vals = find_all(s, "=\"");
        if (vals.empty()) break;
        size_t b, e;
        if (!value_range(s, vals[rng.below(vals.size())], b, e)) break;
        const char* num = kHostileNumbers[rng.below(std::size(kHostileNumbers))];
        s.replace(b, e - b, num);
        how += std::string("number:") + num + " ";
        break;
      }
      case 6: {  // swap two type="" values (plugins in the wrong place)
        auto types = find_all(s, "type=\"");
        if (types.size() < 2) break;
        size_t a0, a1, b0, b1;
        size_t ia = rng.below(types.size()), ib = rng.below(types.size());
        if (ia >= ib) break;
        if (!value_range(s, types[ia], a0, a1) || !value_range(s, types[ib], b0, b1) || a1 >= b0) break;
        std::string va = s.substr(a0, a1 - a0), vb = s.substr(b0, b1 - b0);
        s.replace(b0, b1 - b0, va);
        s.replace(a0, a1 - a0, vb);
        how += "swaptypes ";
        break;
      }
      case 7: {  // insert junk
        const char* j = kJunk[rng.below(std::size(kJunk))];
        size_t len = j[0] == '\0' ? 1 : std::char_traits<char>::length(j);
        s.insert(rng.below(s.size()), std::string(j, len));
        how += "junk ";
        break;
      }
      case 8: {  // deep nesting inside the scene
        size_t at = s.find('>', s.find("<scene"));
        if (at == std::string::npos) break;
        int depth = 1 + int(rng.below(200));
        std::string open, close;
        for (int i = 0; i < depth; ++i) {
          open += "<bsdf type=\"twosided\">";
          close += "</bsdf>";
        }
        s.insert(at + 1, open + "<bsdf type=\"diffuse\"/>" + close);
        how += "nest*" + std::to_string(depth) + " ";
        break;
      }
    }
  }
  return s;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(LoaderFuzz, MutatedRealScenesNeverCrash) {
  std::vector<SceneText> scenes = {
      {"cornell-box", "", "", true, 30}, {"veach-mis", "", "", true, 30}, {"veach-bidir", "", "", false, 10},
      {"living-room", "", "", false, 8}, {"staircase2", "", "", false, 8}, {"kitchenette", "", "", false, 9},
      {"bathroom", "", "", false, 5}};
  int total_weight = 0;
  for (auto& sc : scenes) {
    sc.path = test::shared_path("scenes/" + sc.name + "/scene.xml");
    TESSERA_REQUIRE_FILE(sc.path);
    sc.text = read_file(sc.path);
    total_weight += sc.weight;
  }
  const int kIterations = int(env_or("TESSERA_FUZZ_ITERATIONS", kDefaultIterations));
  Rng rng{env_or("TESSERA_FUZZ_SEED", 20240607)};
  int parsed = 0, loaded = 0, scene_errors = 0;
  for (int it = 0; it < kIterations; ++it) {
    size_t pick = rng.below(size_t(total_weight));
    const SceneText* sc = &scenes[0];
    for (const auto& c : scenes) {
      if (pick < size_t(c.weight)) {
        sc = &c;
        break;
      }
      pick -= size_t(c.weight);
    }
    std::string how;
    std::string text = mutate(sc->text, rng, how);
    try {
      // Named as the real file, so relative includes and mesh files resolve against the scene.
      SceneDesc desc = parse_scene_string(text, sc->path);
      ++parsed;
      if (!sc->load) continue;
      LoadOptions opt;
      opt.allow_unsupported = rng.chance(80);
      LoadResult r = load_scene(desc, opt);
      ASSERT_NE(r.scene, nullptr);
      ++loaded;
    } catch (const SceneError&) {
      ++scene_errors;
    } catch (const std::exception& e) {
      FAIL() << "iteration " << it << " (" << sc->name << ", " << how << "): non-SceneError exception: " << e.what();
    }
  }
  // The mutations are mild enough that a fair share still parses and loads.
  EXPECT_GT(parsed, kIterations / 10);
  EXPECT_GT(loaded, kIterations / 50);
  EXPECT_GT(scene_errors, kIterations / 10);
  std::printf("fuzz: %d iterations, %d parsed, %d loaded, %d SceneErrors\n", kIterations, parsed, loaded, scene_errors);
}

}  // namespace
}  // namespace tessera
