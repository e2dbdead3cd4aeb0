// `tessera compare`: error of a render against a reference image (relMSE, with and without the worst
// 0.1% of pixels, MSE, channel means; with the reference's per-pixel variance a z-score summary and
// the relMSE the reference's own noise adds). Used by bench/ scripts and by people.
#include "tessera/cli/command_line.h"
#include "tessera/cli/commands.h"
#include "tessera/cli/convergence.h"
#include "tessera/image/image.h"
#include "tessera/image/image_compare.h"
#include "tessera/scene/error.h"

#include <cstdio>
#include <exception>
#include <memory>

namespace tessera::cli {

int run_compare(const CompareOptions& options) {
  try {
    Image image = read_image(options.image).to_rgb();
    Image ref = read_image(options.reference).to_rgb();
    if (image.width() != ref.width() || image.height() != ref.height()) {
      std::fprintf(stderr, "error: %s is %s but %s is %s\n", options.image.c_str(), describe_size(image).c_str(),
                   options.reference.c_str(), describe_size(ref).c_str());
      return 1;
    }
    auto m = channel_means(image);
    auto r = channel_means(ref);
    std::printf("compare rel_mse=%.6g rel_mse_trim=%.6g mse=%.6g mean=%.6g,%.6g,%.6g ref_mean=%.6g,%.6g,%.6g non_finite=%zu",
                rel_mse(image, ref), measure_error(image, ref).rel_mse_trim, mse(image, ref), m[0], m[1], m[2], r[0], r[1],
                r[2], count_non_finite(image));
    if (!options.variance.empty()) {
      Image var = read_image(options.variance).to_rgb();
      ZScoreStats z = z_score_stats(image, ref, var);
      std::printf(" z_mean=%.4f z_mean_sq=%.4f frac_z_above_4=%.6f ref_floor=%.6g", z.mean_z, z.mean_z2, z.frac_above_4,
                  rel_mse_floor(ref, var));
    }
    std::printf("\n");
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

Command add_compare_command(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* c = app.add_subcommand("compare", "Error of an image against a reference (relMSE, means, z-scores)");
  c->add_option("image", o->image, "Rendered image (.exr/.pfm/.hdr)")->required()->check(CLI::ExistingFile);
  c->add_option("reference", o->reference, "Reference image")->required()->check(CLI::ExistingFile);
  c->add_option("--variance", o->variance, "Per-pixel variance of the reference")->check(CLI::ExistingFile);
  return {c, [o] { return run_compare(*o); }};
}

}  // namespace tessera::cli
