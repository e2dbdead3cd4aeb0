#include "strategy_images.h"

#include "tessera/image/image.h"
#include "tessera/render/bdpt.h"

#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace tessera::cli {

namespace {

// Strategies of paths longer than this are many and faint; an unbounded scene stops here.
constexpr int kUnboundedLength = 5;

}  // namespace

int write_strategy_images(Scene& scene, const RenderSettings& settings, const std::string& dir) {
  if (scene.integrator.type != IntegratorType::Bdpt)
    throw std::invalid_argument("--strategy-images: the scene is not rendered by bdpt (use --integrator bdpt)");
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("--strategy-images: cannot make '" + dir + "': " + ec.message());
  const IntegratorSettings saved = scene.integrator;
  const int max_length = saved.max_depth >= 0 ? saved.max_depth : kUnboundedLength;
  int written = 0;
  for (const auto& [s, t] : bdpt_strategies(max_length)) {
    scene.integrator.only_s = s;
    scene.integrator.only_t = t;
    scene.integrator.only_weighted = true;
    const Image image = render(scene, settings).to_image();
    write_exr((std::filesystem::path(dir) / ("s" + std::to_string(s) + "_t" + std::to_string(t) + ".exr")).string(),
              image);
    ++written;
  }
  scene.integrator = saved;
  return written;
}

}  // namespace tessera::cli
