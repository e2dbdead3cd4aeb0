// Typed look-ups on parsed scene nodes. A wrong type is the user's error, reported where the
// property was written; every successful look-up marks the property consumed.
#include "tessera/scene/scene_desc.h"

#include "tessera/scene/parameter_log.h"

namespace tessera {

namespace {

const char* type_name(PropType t) {
  switch (t) {
    case PropType::Boolean: return "a boolean";
    case PropType::Integer: return "an integer";
    case PropType::Float: return "a float";
    case PropType::String: return "a string";
    case PropType::Color: return "a colour";
    case PropType::Vector: return "a point/vector";
    case PropType::Transform: return "a transform";
    case PropType::Animation: return "an animated transform";
  }
  return "?";
}

[[noreturn]] void wrong_type(const SceneNode& node, const Property& p, const char* expected) {
  throw SceneError(p.loc, "parameter '" + p.written_name + "' of " + node.describe() + " must be " +
                              expected + ", not " + type_name(p.type));
}

}  // namespace

const Property* SceneNode::find(const std::string& n) const {
  ParameterLog::record(*this, n);
  return peek(n);
}

const Property* SceneNode::peek(const std::string& n) const {
  for (const Property& p : props)
    if (p.name == n) return &p;
  return nullptr;
}

float SceneNode::get_float(const std::string& n, float def) const {
  const Property* p = find(n);
  if (!p) return def;
  if (p->type == PropType::Float) {
    p->used = true;
    return float(p->f);
  }
  if (p->type == PropType::Integer) {
    p->used = true;
    return float(p->i);
  }
  wrong_type(*this, *p, "a float");
}

int64_t SceneNode::get_int(const std::string& n, int64_t def) const {
  const Property* p = find(n);
  if (!p) return def;
  if (p->type != PropType::Integer) wrong_type(*this, *p, "an integer");
  p->used = true;
  return p->i;
}

bool SceneNode::get_bool(const std::string& n, bool def) const {
  const Property* p = find(n);
  if (!p) return def;
  if (p->type != PropType::Boolean) wrong_type(*this, *p, "a boolean");
  p->used = true;
  return p->b;
}

std::string SceneNode::get_string(const std::string& n, const std::string& def) const {
  const Property* p = find(n);
  if (!p) return def;
  if (p->type != PropType::String) wrong_type(*this, *p, "a string");
  p->used = true;
  return p->s;
}

Rgb SceneNode::get_color(const std::string& n, Rgb def) const {
  const Property* p = find(n);
  if (!p) return def;
  switch (p->type) {
    case PropType::Color: p->used = true; return p->color;
    case PropType::Float: p->used = true; return Rgb(float(p->f));
    case PropType::Integer: p->used = true; return Rgb(float(p->i));
    default: wrong_type(*this, *p, "a colour or a float");
  }
}

Vec3 SceneNode::get_vector(const std::string& n, Vec3 def) const {
  const Property* p = find(n);
  if (!p) return def;
  if (p->type != PropType::Vector) wrong_type(*this, *p, "a point/vector");
  p->used = true;
  return p->v;
}

tessera::Transform SceneNode::get_transform(const std::string& n, const tessera::Transform& def) const {
  const Property* p = find(n);
  if (!p) return def;
  if (p->type == PropType::Animation)
    throw SceneError(p->loc, "parameter '" + p->written_name + "' of " + describe() +
                                 " is animated (<animation>), which this plugin does not support");
  if (p->type != PropType::Transform) wrong_type(*this, *p, "a transform");
  p->used = true;
  return p->xf;
}

AnimatedTransform SceneNode::get_animated_transform(const std::string& n, const tessera::Transform& def) const {
  const Property* p = find(n);
  if (!p) return AnimatedTransform(def);
  if (p->type != PropType::Transform && p->type != PropType::Animation)
    wrong_type(*this, *p, "a transform or an animation");
  p->used = true;
  return p->type == PropType::Transform ? AnimatedTransform(p->xf) : AnimatedTransform(p->keyframes);
}

std::vector<std::shared_ptr<SceneNode>> SceneNode::children_with_tag(const std::string& t) const {
  std::vector<std::shared_ptr<SceneNode>> out;
  for (const auto& c : children)
    if (c->tag == t) out.push_back(c);
  return out;
}

std::shared_ptr<SceneNode> SceneNode::named_child(const std::string& n) const {
  ParameterLog::record(*this, n);
  for (size_t i = 0; i < children.size() && i < child_names.size(); ++i)
    if (child_names[i] == n) return children[i];
  return nullptr;
}

std::string SceneNode::describe() const {
  std::string s = type.empty() ? tag : tag + " '" + type + "'";
  if (!id.empty()) s += " (id '" + id + "')";
  return s;
}

}  // namespace tessera
