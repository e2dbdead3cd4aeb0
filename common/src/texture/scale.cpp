// Mitsuba 0.6's `scale` texture: a nested texture (or a `value` colour) times `scale`.
#include "tessera/scene/load_context.h"

namespace tessera {

namespace {

class ScaleTexture final : public Texture {
 public:
  ScaleTexture(std::shared_ptr<Texture> nested, Rgb scale) : nested_(std::move(nested)), scale_(scale) {}
  Rgb eval(const SurfaceInteraction& si) const override { return nested_->eval(si) * scale_; }
  Rgb mean() const override { return nested_->mean() * scale_; }
  // Exact for a grey scale (what bump maps use); a coloured one is reduced to its average, since
  // the nested gradient is already a scalar.
  Vec2 eval_1_gradient(const SurfaceInteraction& si) const override {
    return nested_->eval_1_gradient(si) * scale_.average();
  }

 private:
  std::shared_ptr<Texture> nested_;
  Rgb scale_;
};

}  // namespace

std::shared_ptr<Texture> make_scale(const SceneNode& node, LoadContext& ctx) {
  // 0.6 takes the nested texture whatever its name; `value` is the constant alternative.
  std::shared_ptr<Texture> nested;
  for (size_t i = 0; i < node.children.size() && i < node.child_names.size(); ++i) {
    if (node.children[i]->tag != "texture") continue;
    if (nested)
      throw SceneError(node.children[i]->loc, node.describe() + " takes one nested texture");
    const std::string& name = node.child_names[i];
    if (node.named_child(name) != node.children[i])
      throw SceneError(node.children[i]->loc, node.describe() + ": two nested objects named '" + name + "'");
    nested = ctx.texture(node, name, Rgb(1.f));
  }
  if (!nested) {
    if (!node.has("value"))
      throw SceneError(node.loc, node.describe() + " needs a nested texture or a 'value'");
    nested = std::make_shared<ConstantTexture>(node.get_color("value", Rgb(1.f)));
  } else if (node.has("value")) {
    throw SceneError(node.find("value")->loc, node.describe() + " has both a nested texture and a 'value'");
  }
  Rgb scale = node.get_color("scale", Rgb(1.f));  // a float is read as grey
  return std::make_shared<ScaleTexture>(std::move(nested), scale);
}

}  // namespace tessera
