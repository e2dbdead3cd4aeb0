// Ray/hit file containers, the OBJ soup order, and the bathroom check against Embree's answers.
#include "test_support.h"
#include "tessera/accel/obj_soup.h"
#include "tessera/accel/rayfile.h"
#include "tessera/scene/error.h"
#include "tessera/tools/bench_rays.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace tessera {
namespace {

namespace fs = std::filesystem;

/// A fresh folder under the build's temp dir, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& name) : path_(fs::temp_directory_path() / ("tessera_accel_" + name)) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string file(const std::string& rel) const { return (path_ / rel).string(); }

 private:
  fs::path path_;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void spit(const std::string& path, const std::string& data) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << data;
}

RayFile sample_rays() {
  RayFile f;
  f.info = "test rays; ünïcode";
  RaySet a{"primary", RayQuery::Closest, {}};
  a.rays.push_back(Ray{Vec3(1, 2, 3), Vec3(0, 0, 1), 0.f, kInfinity});
  a.rays.push_back(Ray{Vec3(-1e30f, 0.5f, -0.f), Vec3(0.6f, 0.8f, 0), 1e-4f, 5.f});
  RaySet b{"sixteen_chars_ab", RayQuery::Occlusion, {}};
  b.rays.push_back(Ray{Vec3(4, 5, 6), Vec3(1, 0, 0), 0.f, 2.5f});
  RaySet c{"empty", RayQuery::Closest, {}};
  f.sets = {a, b, c};
  return f;
}

TEST(RayFile, RoundTripIsExact) {
  TempDir dir("roundtrip");
  const RayFile f = sample_rays();
  write_ray_file(dir.file("a.rays"), f);
  const RayFile g = read_ray_file(dir.file("a.rays"));
  EXPECT_EQ(g.info, f.info);
  ASSERT_EQ(g.sets.size(), 3u);
  for (size_t s = 0; s < 3; ++s) {
    EXPECT_EQ(g.sets[s].name, f.sets[s].name);
    EXPECT_EQ(g.sets[s].query, f.sets[s].query);
    ASSERT_EQ(g.sets[s].rays.size(), f.sets[s].rays.size());
    for (size_t i = 0; i < f.sets[s].rays.size(); ++i) {
      const Ray &x = f.sets[s].rays[i], &y = g.sets[s].rays[i];
      EXPECT_EQ(std::memcmp(&x, &y, sizeof(Ray)), 0);
    }
  }
  // Writing what was read gives the same bytes.
  write_ray_file(dir.file("b.rays"), g);
  EXPECT_EQ(slurp(dir.file("a.rays")), slurp(dir.file("b.rays")));

  HitFile h{"hits", {{"primary", RayQuery::Closest, {{1.5f, 7}, {kInfinity, HitRecord::kNoHit}}},
                     {"sixteen_chars_ab", RayQuery::Occlusion, {{0.f, 0}}}}};
  write_hit_file(dir.file("a.hits"), h);
  const HitFile k = read_hit_file(dir.file("a.hits"));
  ASSERT_EQ(k.sets.size(), 2u);
  EXPECT_EQ(k.info, "hits");
  EXPECT_EQ(k.sets[0].hits[0].t, 1.5f);
  EXPECT_EQ(k.sets[0].hits[0].prim, 7u);
  EXPECT_FALSE(k.sets[0].hits[1].is_hit());
  EXPECT_TRUE(k.sets[1].hits[0].is_hit());
  EXPECT_NO_THROW(check_hits_match_rays(RayFile{"", {f.sets[0], f.sets[1]}}, HitFile{"", {h.sets[0], h.sets[1]}}, "x"));
}

TEST(RayFile, LayoutIsLittleEndianAsSpecified) {
  TempDir dir("layout");
  RayFile f;
  f.info = "ab";
  f.sets.push_back(RaySet{"shadow", RayQuery::Occlusion, {Ray{Vec3(1, 0, 0), Vec3(0, 1, 0), 0.f, 2.f}}});
  write_ray_file(dir.file("x.rays"), f);
  const std::string b = slurp(dir.file("x.rays"));
  ASSERT_EQ(b.size(), 24u + 2u + 32u + 32u);
  EXPECT_EQ(b.substr(0, 8), "RBRAYS01");
  EXPECT_EQ(b.substr(8, 4), std::string("\x01\0\0\0", 4));   // version
  EXPECT_EQ(b.substr(12, 4), std::string("\x01\0\0\0", 4));  // num_sets
  EXPECT_EQ(b.substr(16, 4), std::string("\x02\0\0\0", 4));  // info_len
  EXPECT_EQ(b.substr(26, 16), std::string("shadow\0\0\0\0\0\0\0\0\0\0", 16));
  EXPECT_EQ(b.substr(42, 4), std::string("\x01\0\0\0", 4));   // query
  EXPECT_EQ(b.substr(46, 4), std::string("\x20\0\0\0", 4));   // record size
  EXPECT_EQ(b.substr(50, 8), std::string("\x01\0\0\0\0\0\0\0", 8));
  EXPECT_EQ(b.substr(58, 4), std::string("\0\0\x80\x3f", 4));  // org.x = 1.0f
  EXPECT_EQ(b.substr(86, 4), std::string("\0\0\0\x40", 4));    // tfar = 2.0f
}

void expect_error(const std::string& path, const std::string& needle) {
  try {
    read_ray_file(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const RayFileError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(RayFile, RejectsMalformedFiles) {
  TempDir dir("errors");
  write_ray_file(dir.file("good.rays"), sample_rays());
  const std::string good = slurp(dir.file("good.rays"));

  expect_error(dir.file("missing.rays"), "cannot open");
  std::string bad = good;
  bad[2] = 'X';
  spit(dir.file("magic.rays"), bad);
  expect_error(dir.file("magic.rays"), "bad magic");
  spit(dir.file("hits_as_rays.rays"), "RBHITS01" + good.substr(8));
  expect_error(dir.file("hits_as_rays.rays"), "bad magic");
  spit(dir.file("short.rays"), good.substr(0, 10));
  expect_error(dir.file("short.rays"), "truncated file header");
  spit(dir.file("trunc.rays"), good.substr(0, good.size() - 40));
  expect_error(dir.file("trunc.rays"), "truncated");
  spit(dir.file("trailing.rays"), good + "xyz");
  expect_error(dir.file("trailing.rays"), "unexpected bytes");
  bad = good;
  bad[8] = 2;
  spit(dir.file("version.rays"), bad);
  expect_error(dir.file("version.rays"), "version");
  // Record size of the first set (after the 24-byte header, the info text and the 16-byte name).
  bad = good;
  const size_t set0 = 24 + sample_rays().info.size();
  bad[set0 + 20] = 8;
  spit(dir.file("recsize.rays"), bad);
  expect_error(dir.file("recsize.rays"), "record size");
  bad = good;
  bad[set0 + 16] = 5;
  spit(dir.file("query.rays"), bad);
  expect_error(dir.file("query.rays"), "unknown query");
  EXPECT_THROW(read_hit_file(dir.file("good.rays")), RayFileError);
}

TEST(RayFile, CountMismatchIsReported) {
  const RayFile rays = sample_rays();
  HitFile hits;
  for (const RaySet& s : rays.sets) hits.sets.push_back({s.name, s.query, std::vector<HitRecord>(s.rays.size())});
  EXPECT_NO_THROW(check_hits_match_rays(rays, hits, "h"));
  HitFile fewer = hits;
  fewer.sets[0].hits.pop_back();
  EXPECT_THROW(check_hits_match_rays(rays, fewer, "h"), RayFileError);
  EXPECT_THROW(compare_hit_files(hits, fewer), RayFileError);
  HitFile renamed = hits;
  renamed.sets[1].name = "other";
  EXPECT_THROW(check_hits_match_rays(rays, renamed, "h"), RayFileError);
  HitFile missing = hits;
  missing.sets.pop_back();
  EXPECT_THROW(compare_hit_files(hits, missing), RayFileError);
}

TEST(RayFile, AgreementRule) {
  const HitRecord miss;
  EXPECT_TRUE(hits_agree(miss, miss));
  EXPECT_FALSE(hits_agree(miss, HitRecord{1.f, 3}));
  EXPECT_TRUE(hits_agree(HitRecord{100.f, 3}, HitRecord{100.009f, 9}));  // prim may differ
  EXPECT_FALSE(hits_agree(HitRecord{100.f, 3}, HitRecord{100.02f, 3}));
  EXPECT_TRUE(hits_agree(HitRecord{0.f, 0}, HitRecord{0.f, 0}));  // occluded
  HitFile a{"", {{"s", RayQuery::Closest, {{1.f, 0}, {2.f, 1}, miss, miss}}}};
  HitFile b{"", {{"s", RayQuery::Closest, {{1.f, 0}, {2.5f, 1}, miss, {4.f, 2}}}}};
  const auto cmp = compare_hit_files(a, b);
  ASSERT_EQ(cmp.size(), 1u);
  EXPECT_EQ(cmp[0].disagree, 2u);
  EXPECT_DOUBLE_EQ(cmp[0].fraction(), 0.5);
}

TEST(ObjSoup, FolderOrderAndTriangulation) {
  TempDir dir("objsoup");
  // b.obj: a quad (two triangles) in one object; sub/a.obj: a triangle and a pentagon (three).
  spit(dir.file("root/b.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  spit(dir.file("root/sub/a.obj"),
       "o first\nv 0 0 5\nv 1 0 5\nv 0 1 5\nf 1 2 3\no second\nv 0 0 7\nv 2 0 7\nv 3 1 7\nv 1 2 7\nv -1 1 7\nf 4 5 6 7 8\n");
  spit(dir.file("root/c.txt"), "not an obj");
  spit(dir.file("extra.obj"), "v 0 0 9\nv 1 0 9\nv 0 1 9\nf -3 -2 -1\n");

  const auto files = expand_obj_paths({dir.file("extra.obj"), dir.file("root")});
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(fs::path(files[0]).filename(), "extra.obj");
  EXPECT_EQ(fs::path(files[1]).filename(), "b.obj");   // ".../root/b.obj" < ".../root/sub/a.obj"
  EXPECT_EQ(fs::path(files[2]).filename(), "a.obj");

  const ObjSoup soup = load_obj_soup({dir.file("extra.obj"), dir.file("root")});
  ASSERT_EQ(soup.triangles.size(), 1u + 2u + 1u + 3u);
  EXPECT_EQ(soup.triangles[0][0].z, 9.f);
  EXPECT_EQ(soup.triangles[1][0].z, 0.f);
  EXPECT_EQ(soup.triangles[2][0].z, 0.f);
  EXPECT_EQ(soup.triangles[3][1], Vec3(1, 0, 5));
  for (size_t i = 4; i < 7; ++i) EXPECT_EQ(soup.triangles[i][0].z, 7.f);

  EXPECT_THROW(load_obj_soup({dir.file("nope")}), SceneError);
}

TEST(BenchRays, SmallSceneWritesAndComparesHits) {
  TempDir dir("bench");
  spit(dir.file("quad.obj"), "v -1 -1 2\nv 1 -1 2\nv 1 1 2\nv -1 1 2\nf 1 2 3 4\n");
  RayFile rays;
  rays.sets.push_back({"primary", RayQuery::Closest,
                       {Ray{Vec3(0.25f, 0.5f, 0), Vec3(0, 0, 1)}, Ray{Vec3(5, 0, 0), Vec3(0, 0, 1)}}});
  rays.sets.push_back({"shadow", RayQuery::Occlusion,
                       {Ray{Vec3(0.f), Vec3(0, 0, 1), 0.f, 1.5f}, Ray{Vec3(0.f), Vec3(0, 0, 1), 0.f, 3.f}}});
  write_ray_file(dir.file("r.rays"), rays);

  BenchRaysOptions opt;
  opt.geometry = {dir.file("quad.obj")};
  opt.rays = dir.file("r.rays");
  opt.hits_out = dir.file("r.hits");
  opt.threads = 1;
  std::ostringstream out;
  const BenchRaysResult r = bench_rays(opt, out);
  EXPECT_EQ(r.primitives, 2u);
  ASSERT_EQ(r.sets.size(), 2u);
  EXPECT_EQ(r.sets[0].hits, 1u);
  EXPECT_EQ(r.sets[1].hits, 1u);
  const HitFile h = read_hit_file(dir.file("r.hits"));
  EXPECT_FLOAT_EQ(h.sets[0].hits[0].t, 2.f);
  EXPECT_FALSE(h.sets[0].hits[1].is_hit());
  EXPECT_FALSE(h.sets[1].hits[0].is_hit());
  EXPECT_EQ(h.sets[1].hits[1].t, 0.f);
  EXPECT_EQ(h.sets[1].hits[1].prim, 0u);
  const std::string text = out.str();
  EXPECT_NE(text.find("build triangles=2 threads=1"), std::string::npos) << text;
  EXPECT_NE(text.find("rays set=primary n=2 mrays_per_s="), std::string::npos) << text;
  EXPECT_NE(text.find("rays set=shadow n=2 mrays_per_s="), std::string::npos) << text;

  // Against its own answers nothing disagrees; against a doctored copy one ray does.
  opt.compare = opt.hits_out;
  opt.hits_out.clear();
  EXPECT_EQ(bench_rays(opt, out).sets[0].disagree, 0u);
  HitFile doctored = h;
  doctored.sets[0].hits[1] = HitRecord{3.f, 0};
  write_hit_file(dir.file("doctored.hits"), doctored);
  opt.compare = dir.file("doctored.hits");
  const BenchRaysResult c = bench_rays(opt, out);
  EXPECT_EQ(c.sets[0].disagree, 1u);
  EXPECT_EQ(c.sets[1].disagree, 0u);
  EXPECT_NE(out.str().find("compare set=primary disagree=1 fraction=0.5"), std::string::npos) << out.str();
}

TEST(BenchRays, BathroomAgreesWithEmbree) {
  const std::string models = test::shared_path("scenes/bathroom/models");
  const std::string rays = test::shared_path("rays/bathroom.rays");
  const std::string reference = test::shared_path("rays/bathroom.embree.hits");
  TESSERA_REQUIRE_FILE(models);
  TESSERA_REQUIRE_FILE(rays);
  TESSERA_REQUIRE_FILE(reference);
  BenchRaysOptions opt;
  opt.geometry = {models};
  opt.rays = rays;
  opt.compare = reference;
  opt.threads = 2;
  std::ostringstream out;
  const BenchRaysResult r = bench_rays(opt, out);
  EXPECT_EQ(r.primitives, 592186u);
  ASSERT_EQ(r.sets.size(), 3u);
  const char* names[] = {"primary", "diffuse", "shadow"};
  const uint64_t counts[] = {230400, 216121, 140536};
  for (size_t s = 0; s < 3; ++s) {
    EXPECT_EQ(r.sets[s].name, names[s]);
    EXPECT_EQ(r.sets[s].count, counts[s]);
    ASSERT_TRUE(r.sets[s].compared);
    EXPECT_LT(r.sets[s].disagree_fraction, 1e-4) << names[s] << ": " << r.sets[s].disagree << " rays";
    EXPECT_GT(r.sets[s].hits, r.sets[s].count / 10) << names[s];
  }
  std::cout << out.str();
}

}  // namespace
}  // namespace tessera
