// Named measured media (Mitsuba 0.6 `material` presets): values, units, name matching.
#include "tessera/medium/material_presets.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>
#include <set>
#include <string>
#include <vector>

namespace tessera {
namespace {

void expect_rgb_near(Rgb got, Rgb want, float rel, float abs, const std::string& what) {
  for (int c = 0; c < 3; ++c) {
    float tol = std::max(abs, rel * std::abs(want[c]));
    EXPECT_NEAR(got[c], want[c], tol) << what << " channel " << c;
  }
}

MeasuredMedium must_find(const std::string& name) {
  MeasuredMedium m;
  EXPECT_TRUE(lookup_measured_medium(name, m)) << name;
  return m;
}

// Jensen et al. 2001, Table 1 (sigma_s' and sigma_a in 1/mm, eta): reduced scattering is stored as
// published, so these come back unchanged.
TEST(MaterialPresets, JensenRowsAreReducedScatteringPerMillimetre) {
  MeasuredMedium apple = must_find("Apple");
  EXPECT_EQ(apple.sigma_s, Rgb(2.29f, 2.39f, 1.97f));
  EXPECT_EQ(apple.sigma_a, Rgb(0.0030f, 0.0034f, 0.046f));
  EXPECT_FLOAT_EQ(apple.eta, 1.3f);

  MeasuredMedium skin1 = must_find("Skin1");
  EXPECT_EQ(skin1.sigma_s, Rgb(0.74f, 0.88f, 1.01f));
  EXPECT_EQ(skin1.sigma_a, Rgb(0.032f, 0.17f, 0.48f));

  MeasuredMedium ketchup = must_find("Ketchup");
  EXPECT_EQ(ketchup.sigma_s, Rgb(0.18f, 0.07f, 0.03f));
  EXPECT_EQ(ketchup.sigma_a, Rgb(0.061f, 0.97f, 1.45f));

  // Marble is the one Jensen row with eta 1.5.
  MeasuredMedium marble = must_find("Marble");
  EXPECT_EQ(marble.sigma_s, Rgb(2.19f, 2.62f, 3.00f));
  EXPECT_FLOAT_EQ(marble.eta, 1.5f);

  // Paper value 0.015 (Mitsuba 0.6's table says 0.0015: a transcription slip, see the .cpp).
  EXPECT_FLOAT_EQ(must_find("Chicken1").sigma_a.r, 0.015f);
  EXPECT_FLOAT_EQ(must_find("Chicken2").sigma_a.r, 0.018f);
}

// Narasimhan et al. 2006 rows: Mitsuba stores sigma_s and g, and uses sigma_s (1 - g). Lowfat Milk:
// sigma_s = 13.1157, g = 0.932 (red) -> 0.89187 1/mm; sigma_a is used as stored.
TEST(MaterialPresets, NarasimhanRowsFoldAnisotropyIntoSigmaS) {
  MeasuredMedium milk = must_find("Lowfat Milk");
  EXPECT_NEAR(milk.sigma_s.r, 13.1157f * (1.f - 0.932f), 1e-5f);
  EXPECT_NEAR(milk.sigma_s.r, 0.89187f, 1e-4f);
  EXPECT_EQ(milk.sigma_a, Rgb(0.00287f, 0.00575f, 0.01150f));
  EXPECT_FLOAT_EQ(milk.eta, 1.33f);

  MeasuredMedium espresso = must_find("Espresso");
  EXPECT_EQ(espresso.sigma_a, Rgb(4.79838f, 6.57512f, 8.84925f));
  EXPECT_LT(espresso.sigma_s.max_value(), 1.1f);  // reduced: ~0.72..1.02, not the raw 7.8..8.5
}

// Every row against pbrt-v3's independent transcription of the same two papers (src/core/medium.cpp,
// commit 2f208c19, "mm^-1", sigma_prime_s already reduced). pbrt prints 5 significant digits of the
// reduced value while Mitsuba rounds sigma_s to 5 decimals, so tiny coefficients differ by a few %.
TEST(MaterialPresets, AgreesWithPbrtV3Transcription) {
  struct Ref {
    const char* name;
    Rgb sigma_prime_s, sigma_a;
  };
  const Ref refs[] = {
      {"Apple", {2.29f, 2.39f, 1.97f}, {0.0030f, 0.0034f, 0.046f}},
      {"Chicken1", {0.15f, 0.21f, 0.38f}, {0.015f, 0.077f, 0.19f}},
      {"Chicken2", {0.19f, 0.25f, 0.32f}, {0.018f, 0.088f, 0.20f}},
      {"Cream", {7.38f, 5.47f, 3.15f}, {0.0002f, 0.0028f, 0.0163f}},
      {"Ketchup", {0.18f, 0.07f, 0.03f}, {0.061f, 0.97f, 1.45f}},
      {"Marble", {2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}},
      {"Potato", {0.68f, 0.70f, 0.55f}, {0.0024f, 0.0090f, 0.12f}},
      {"Skimmilk", {0.70f, 1.22f, 1.90f}, {0.0014f, 0.0025f, 0.0142f}},
      {"Skin1", {0.74f, 0.88f, 1.01f}, {0.032f, 0.17f, 0.48f}},
      {"Skin2", {1.09f, 1.59f, 1.79f}, {0.013f, 0.070f, 0.145f}},
      {"Spectralon", {11.6f, 20.4f, 14.9f}, {0.f, 0.f, 0.f}},
      {"Wholemilk", {2.55f, 3.21f, 3.77f}, {0.0011f, 0.0024f, 0.014f}},
      {"Lowfat Milk", {0.89187f, 1.5136f, 2.532f}, {0.002875f, 0.00575f, 0.0115f}},
      {"Reduced Milk", {2.4858f, 3.1669f, 4.5214f}, {0.0025556f, 0.0051111f, 0.012778f}},
      {"Regular Milk", {4.5513f, 5.8294f, 7.136f}, {0.0015333f, 0.0046f, 0.019933f}},
      {"Espresso", {0.72378f, 0.84557f, 1.0247f}, {4.7984f, 6.5751f, 8.8493f}},
      {"Mint Mocha Coffee", {0.31602f, 0.38538f, 0.48131f}, {3.772f, 5.8228f, 7.82f}},
      {"Lowfat Soy Milk", {0.30576f, 0.34233f, 0.61664f}, {0.0014375f, 0.0071875f, 0.035937f}},
      {"Regular Soy Milk", {0.59223f, 0.73866f, 1.4693f}, {0.0019167f, 0.0095833f, 0.065167f}},
      {"Lowfat Chocolate Milk", {0.64925f, 0.83916f, 1.1057f}, {0.0115f, 0.0368f, 0.1564f}},
      {"Regular Chocolate Milk", {1.4585f, 2.1289f, 2.9527f}, {0.010063f, 0.043125f, 0.14375f}},
      {"Coke", {8.9053e-05f, 8.372e-05f, 0.f}, {0.10014f, 0.16503f, 0.2468f}},
      {"Pepsi", {6.1697e-05f, 4.2564e-05f, 0.f}, {0.091641f, 0.14158f, 0.20729f}},
      {"Sprite", {6.0306e-06f, 6.4139e-06f, 6.5504e-06f}, {0.001886f, 0.0018308f, 0.0020025f}},
      {"Gatorade", {0.0024574f, 0.003007f, 0.0037325f}, {0.024794f, 0.019289f, 0.008878f}},
      {"Chardonnay", {1.7982e-05f, 1.3758e-05f, 1.2023e-05f}, {0.010782f, 0.011855f, 0.023997f}},
      {"White Zinfandel", {1.7501e-05f, 1.9069e-05f, 1.288e-05f}, {0.012072f, 0.016184f, 0.019843f}},
      {"Merlot", {2.1129e-05f, 0.f, 0.f}, {0.11632f, 0.25191f, 0.29434f}},
      {"Budweiser Beer", {2.4356e-05f, 2.4079e-05f, 1.0564e-05f}, {0.011492f, 0.024911f, 0.057786f}},
      {"Coors Light Beer", {5.0922e-05f, 4.301e-05f, 0.f}, {0.006164f, 0.013984f, 0.034983f}},
      {"Clorox", {0.0024035f, 0.0031373f, 0.003991f}, {0.0033542f, 0.014892f, 0.026297f}},
      {"Apple Juice", {0.00013612f, 0.00015836f, 0.000227f}, {0.012957f, 0.023741f, 0.052184f}},
      {"Cranberry Juice", {0.00010402f, 0.00011646f, 7.8139e-05f}, {0.039437f, 0.094223f, 0.12426f}},
      {"Grape Juice", {5.382e-05f, 0.f, 0.f}, {0.10404f, 0.23958f, 0.29325f}},
      {"Ruby Grapefruit Juice", {0.011002f, 0.010927f, 0.011036f}, {0.085867f, 0.18314f, 0.25262f}},
      {"White Grapefruit Juice", {0.22826f, 0.23998f, 0.32748f}, {0.0138f, 0.018831f, 0.056781f}},
      {"Shampoo", {0.0007176f, 0.0008303f, 0.0009016f}, {0.014107f, 0.045693f, 0.061717f}},
      {"Strawberry Shampoo", {0.00015671f, 0.00015947f, 1.518e-05f}, {0.01449f, 0.05796f, 0.075823f}},
      {"Head & Shoulders Shampoo", {0.023805f, 0.028804f, 0.034306f}, {0.084621f, 0.15688f, 0.20365f}},
      {"Lemon Tea Powder", {0.040224f, 0.045264f, 0.051081f}, {2.4288f, 4.5757f, 7.2127f}},
      {"Orange Juice Powder", {0.00015617f, 0.00017482f, 0.0001762f}, {0.001449f, 0.003441f, 0.007863f}},
      {"Pink Lemonade Powder", {0.00012103f, 0.00013073f, 0.00012528f}, {0.001165f, 0.002366f, 0.003195f}},
      {"Cappuccino Powder", {1.8436f, 2.5851f, 2.1662f}, {35.844f, 49.547f, 61.084f}},
      {"Salt Powder", {0.027333f, 0.032451f, 0.031979f}, {0.28415f, 0.3257f, 0.34148f}},
      {"Sugar Powder", {0.00022272f, 0.00025513f, 0.000271f}, {0.012638f, 0.031051f, 0.050124f}},
      {"Suisse Mocha Powder", {2.7979f, 3.5452f, 4.3365f}, {17.502f, 27.004f, 35.433f}},
      {"Pacific Ocean Surface Water", {0.0001764f, 0.00032095f, 0.00019617f}, {0.031845f, 0.031324f, 0.030147f}},
  };
  EXPECT_EQ(std::size(refs), measured_medium_names().size());
  for (const Ref& ref : refs) {
    MeasuredMedium m = must_find(ref.name);
    // Mitsuba rounds to 5 decimals (abs 5e-6), pbrt to 5 significant digits (rel 1e-4 or so);
    // a transposed or dropped digit in either table is far outside this.
    expect_rgb_near(m.sigma_a, ref.sigma_a, 2e-3f, 6e-6f, std::string(ref.name) + " sigma_a");
    expect_rgb_near(m.sigma_s, ref.sigma_prime_s, 2e-3f, 6e-6f, std::string(ref.name) + " sigma_s");
  }
}

TEST(MaterialPresets, NameMatchingIsCaseInsensitiveButOtherwiseExact) {
  MeasuredMedium a, b;
  ASSERT_TRUE(lookup_measured_medium("skin1", a));  // Mitsuba's documented default spelling
  ASSERT_TRUE(lookup_measured_medium("SKIN1", b));
  EXPECT_EQ(a.sigma_s, b.sigma_s);
  EXPECT_TRUE(lookup_measured_medium("lowfat milk", a));
  EXPECT_TRUE(lookup_measured_medium("HEAD & SHOULDERS SHAMPOO", a));
  // Mitsuba compares the lower-cased strings exactly: spaces matter, nothing is trimmed.
  EXPECT_FALSE(lookup_measured_medium("LowfatMilk", a));
  EXPECT_FALSE(lookup_measured_medium(" Skin1", a));
  EXPECT_FALSE(lookup_measured_medium("Skin1 ", a));
  EXPECT_FALSE(lookup_measured_medium("lowfat_milk", a));
}

TEST(MaterialPresets, DocumentationSpellingsAreAliases) {
  MeasuredMedium code, doc;
  ASSERT_TRUE(lookup_measured_medium("Budweiser Beder", code));  // Mitsuba's code spelling
  ASSERT_TRUE(lookup_measured_medium("budweiser beer", doc));    // Mitsuba's docs spelling
  EXPECT_EQ(code.sigma_a, doc.sigma_a);
  ASSERT_TRUE(lookup_measured_medium("Suisse Mocha Powder", code));
  ASSERT_TRUE(lookup_measured_medium("Suisse Mocha", doc));
  EXPECT_EQ(code.sigma_s, doc.sigma_s);
}

TEST(MaterialPresets, UnknownNameReturnsFalseAndLeavesOutputAlone) {
  MeasuredMedium m;
  m.sigma_s = Rgb(7.f);
  m.sigma_a = Rgb(8.f);
  m.eta = 9.f;
  EXPECT_FALSE(lookup_measured_medium("Unobtainium", m));
  EXPECT_FALSE(lookup_measured_medium("", m));
  EXPECT_EQ(m.sigma_s, Rgb(7.f));
  EXPECT_EQ(m.sigma_a, Rgb(8.f));
  EXPECT_EQ(m.eta, 9.f);
}

TEST(MaterialPresets, NamesListIsCompleteUniqueAndResolvable) {
  std::vector<std::string> names = measured_medium_names();
  EXPECT_EQ(names.size(), 47u);  // 12 Jensen + 35 Narasimhan rows, as in Mitsuba 0.6
  EXPECT_EQ(names.front(), "Apple");
  EXPECT_EQ(names.back(), "Pacific Ocean Surface Water");
  std::set<std::string> lowered;
  for (const std::string& n : names) {
    MeasuredMedium m;
    EXPECT_TRUE(lookup_measured_medium(n, m)) << n;
    EXPECT_TRUE(m.sigma_s.is_finite() && m.sigma_a.is_finite()) << n;
    EXPECT_GE(std::min(m.sigma_s.r, std::min(m.sigma_s.g, m.sigma_s.b)), 0.f) << n;
    EXPECT_GE(std::min(m.sigma_a.r, std::min(m.sigma_a.g, m.sigma_a.b)), 0.f) << n;
    std::string l = n;
    for (char& c : l) c = char(std::tolower(static_cast<unsigned char>(c)));
    lowered.insert(l);
  }
  EXPECT_EQ(lowered.size(), names.size());  // no two names collide under case folding
}

}  // namespace
}  // namespace tessera
