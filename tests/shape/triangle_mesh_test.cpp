#include "shape_test_util.h"

#include "tessera/core/hash.h"
#include "tessera/render/shape.h"

#include <cmath>
#include <memory>

namespace tessera {
namespace {

/// Regularized upper incomplete gamma Q(a, x) (Numerical Recipes: series / continued fraction).
double gamma_q(double a, double x) {
  if (x <= 0) return 1.0;
  double gln = std::lgamma(a);
  if (x < a + 1) {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 1000; ++n) {
      ap += 1;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    double del = d * c;
    h *= del;
    if (std::abs(del - 1) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

/// Pearson's chi-square test of observed counts against expected counts; returns the p-value.
double chi2_pvalue(const std::vector<double>& observed, const std::vector<double>& expected) {
  double chi2 = 0;
  int dof = -1;
  for (size_t i = 0; i < observed.size(); ++i) {
    EXPECT_GE(expected[i], 5.0) << "bin " << i << " too small for a chi-square test";
    chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++dof;
  }
  return gamma_q(0.5 * dof, 0.5 * chi2);
}

TEST(ChiSquare, PValueOfKnownQuantiles) {
  // Tabulated: chi2(63 dof) = 92.01 at p = 0.01; chi2(3 dof) = 7.815 at p = 0.05.
  EXPECT_NEAR(gamma_q(31.5, 92.01 / 2), 0.01, 2e-4);
  EXPECT_NEAR(gamma_q(1.5, 7.815 / 2), 0.05, 2e-4);
}

std::shared_ptr<MeshData> mesh_of(std::vector<Vec3> p, std::vector<uint32_t> idx) {
  auto m = std::make_shared<MeshData>();
  m->positions = std::move(p);
  m->indices = std::move(idx);
  return m;
}

/// Four right triangles of areas 0.5, 2, 4.5, 12.5 in the planes z = 0, 1, 2, 3.
std::shared_ptr<MeshData> stacked_triangles() {
  std::vector<Vec3> p;
  std::vector<uint32_t> idx;
  const float legs[4] = {1.f, 2.f, 3.f, 5.f};
  for (int k = 0; k < 4; ++k) {
    float z = float(k), s = legs[k];
    uint32_t b = uint32_t(p.size());
    p.insert(p.end(), {Vec3(0, 0, z), Vec3(s, 0, z), Vec3(0, s, z)});
    idx.insert(idx.end(), {b, b + 1, b + 2});
  }
  return mesh_of(p, idx);
}

TEST(TriangleMeshShape, AreaBoundsAndPdf) {
  TriangleMeshShape shape(stacked_triangles(), false, false);
  EXPECT_FLOAT_EQ(shape.area(), 0.5f + 2.f + 4.5f + 12.5f);
  EXPECT_EQ(shape.num_primitives(), 4u);
  Bounds3 b = shape.bounds();
  EXPECT_EQ(b.lo, Vec3(0, 0, 0));
  EXPECT_EQ(b.hi, Vec3(5, 5, 3));
  Vec3 p, n;
  float pdf = 0;
  shape.sample_area({0.3f, 0.7f}, p, n, pdf);
  EXPECT_FLOAT_EQ(pdf, 1.f / shape.area());
  EXPECT_EQ(n, Vec3(0, 0, 1));
  TriangleMeshShape flipped(stacked_triangles(), true, false);
  flipped.sample_area({0.3f, 0.7f}, p, n, pdf);
  EXPECT_EQ(n, Vec3(0, 0, -1));
}

TEST(TriangleMeshShape, SampleAreaPicksTrianglesByArea) {
  TriangleMeshShape shape(stacked_triangles(), false, false);
  Pcg32 rng(42);
  const int n = 40000;
  std::vector<double> obs(4, 0.0), expd;
  for (int i = 0; i < n; ++i) {
    Vec3 p, nrm;
    float pdf;
    shape.sample_area({rng.next_float(), rng.next_float()}, p, nrm, pdf);
    int k = int(std::lround(p.z));
    ASSERT_GE(k, 0);
    ASSERT_LT(k, 4);
    ASSERT_GE(p.x, 0.f);
    ASSERT_GE(p.y, 0.f);
    ASSERT_LE(p.x + p.y, float(k == 3 ? 5 : k + 1) * (1 + 1e-6f));  // inside its triangle
    obs[size_t(k)] += 1;
  }
  for (double a : {0.5, 2.0, 4.5, 12.5}) expd.push_back(n * a / 19.5);
  EXPECT_GT(chi2_pvalue(obs, expd), 0.01);
}

TEST(TriangleMeshShape, SampleAreaIsUniformOverAnIrregularTriangulation) {
  // The unit square as a fan around an off-centre point, with extra rim vertices: triangles of
  // very different sizes. A uniform sampler fills an 8x8 grid evenly.
  std::vector<Vec3> p = {Vec3(0.23f, 0.71f, 0.f), Vec3(0, 0, 0),    Vec3(0.1f, 0, 0), Vec3(1, 0, 0),
                         Vec3(1, 0.9f, 0),        Vec3(1, 1, 0),    Vec3(0, 1, 0),    Vec3(0, 0.5f, 0)};
  std::vector<uint32_t> idx;
  for (uint32_t k = 1; k < 8; ++k) idx.insert(idx.end(), {0, k, k == 7 ? 1u : k + 1});
  TriangleMeshShape shape(mesh_of(p, idx), false, false);
  ASSERT_NEAR(shape.area(), 1.f, 1e-6f);
  Pcg32 rng(7);
  const int n = 64 * 400;
  std::vector<double> obs(64, 0.0), expd(64, n / 64.0);
  for (int i = 0; i < n; ++i) {
    Vec3 q, nrm;
    float pdf;
    shape.sample_area({rng.next_float(), rng.next_float()}, q, nrm, pdf);
    ASSERT_EQ(nrm, Vec3(0, 0, 1));
    int cx = std::min(7, int(q.x * 8)), cy = std::min(7, int(q.y * 8));
    ASSERT_GE(cx, 0);
    ASSERT_GE(cy, 0);
    obs[size_t(cy * 8 + cx)] += 1;
  }
  EXPECT_GT(chi2_pvalue(obs, expd), 0.01);
}

TEST(TriangleMeshShape, EmptyMeshSamplesWithZeroPdf) {
  TriangleMeshShape shape(mesh_of({}, {}), false, false);
  Vec3 p, n;
  float pdf = 1;
  shape.sample_area({0.5f, 0.5f}, p, n, pdf);
  EXPECT_EQ(pdf, 0.f);
  EXPECT_EQ(shape.area(), 0.f);
}

/// One triangle in z = 1 with tilted vertex normals and uvs.
std::shared_ptr<MeshData> shaded_triangle() {
  auto m = mesh_of({Vec3(0, 0, 1), Vec3(2, 0, 1), Vec3(0, 2, 1)}, {0, 1, 2});
  m->normals = {normalize(Vec3(-1, 0, 1)), normalize(Vec3(1, 0, 1)), Vec3(0, 0, 1)};
  m->uvs = {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};
  return m;
}

SurfaceInteraction hit_triangle(const Shape& shape, float b1, float b2) {
  Ray ray{Vec3(2 * b1, 2 * b2, 5), Vec3(0, 0, -2)};
  Hit hit{2.f, 0, b1, b2};
  SurfaceInteraction si;
  shape.fill_interaction(ray, hit, 0, si);
  return si;
}

TEST(TriangleMeshShape, FillInteractionInterpolates) {
  TriangleMeshShape shape(shaded_triangle(), false, false);
  SurfaceInteraction si = hit_triangle(shape, 0.5f, 0.f);  // midpoint of edge v0-v1
  EXPECT_EQ(si.p, Vec3(1, 0, 1));
  EXPECT_EQ(si.t, 2.f);
  EXPECT_EQ(si.ng, Vec3(0, 0, 1));
  EXPECT_NEAR(si.shading.n.x, 0.f, 1e-6f);
  EXPECT_NEAR(si.shading.n.z, 1.f, 1e-6f);
  EXPECT_NEAR(si.uv.x, 0.5f, 1e-6f);
  EXPECT_NEAR(si.uv.y, 0.f, 1e-6f);
  EXPECT_EQ(si.wo, Vec3(0, 0, 1));
  EXPECT_EQ(si.shape, &shape);
  SurfaceInteraction near_v1 = hit_triangle(shape, 0.9f, 0.f);
  EXPECT_GT(near_v1.shading.n.x, 0.5f);  // follows v1's normal
  // The shading frame is orthonormal.
  EXPECT_NEAR(dot(near_v1.shading.s, near_v1.shading.n), 0.f, 1e-6f);
  EXPECT_NEAR(length(near_v1.shading.t), 1.f, 1e-6f);
}

TEST(TriangleMeshShape, FlipNormalsAndFaceNormals) {
  TriangleMeshShape flipped(shaded_triangle(), true, false);
  SurfaceInteraction si = hit_triangle(flipped, 0.9f, 0.f);
  EXPECT_EQ(si.ng, Vec3(0, 0, -1));
  EXPECT_LT(si.shading.n.x, -0.5f);  // interpolated normal negated too
  EXPECT_LT(si.shading.n.z, 0.f);
  TriangleMeshShape faceted(shaded_triangle(), false, true);
  si = hit_triangle(faceted, 0.9f, 0.f);
  EXPECT_EQ(si.shading.n, Vec3(0, 0, 1));
}

TEST(TriangleMeshShape, ShadingNormalStaysOnTheGeometricSide) {
  auto m = shaded_triangle();
  m->normals = {Vec3(0, 0, -1), Vec3(0, 0, -1), Vec3(0, 0, -1)};  // disagree with the winding
  TriangleMeshShape shape(m, false, false);
  SurfaceInteraction si = hit_triangle(shape, 0.2f, 0.2f);
  EXPECT_GT(dot(si.shading.n, si.ng), 0.f);
}

TEST(TriangleMeshShape, DegenerateInterpolatedNormalFallsBackToGeometric) {
  auto m = shaded_triangle();
  m->normals = {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(1, 0, 0)};
  m->uvs.clear();
  TriangleMeshShape shape(m, false, false);
  SurfaceInteraction si = hit_triangle(shape, 0.5f, 0.f);  // (n0 + n1) / 2 = 0
  EXPECT_EQ(si.shading.n, si.ng);
  EXPECT_EQ(si.uv.x, 0.5f);  // no uvs: barycentrics (b1, b2)
  EXPECT_EQ(si.uv.y, 0.f);
}

}  // namespace
}  // namespace tessera
