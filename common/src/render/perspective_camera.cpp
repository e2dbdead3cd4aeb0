// Mitsuba's `perspective` sensor (pinhole) and `thinlens` sensor (the same projection through a
// circular thin lens): one class, the pinhole being the lens of radius 0.
//
// Mitsuba builds camera_to_sample = scale(-0.5, -0.5 aspect, 1) * translate(-1, -1/aspect, 0) *
// perspective(fov_x, near, far), sample space being [0,1]^2 over the film. Inverting it for a point
// on the image plane z = 1 gives the camera-space direction used below:
//   x = tan(fov_x/2) * (1 - 2 sx),  y = tan(fov_x/2) * (1 - 2 sy) / aspect,  z = 1
// so camera +x lands on the LEFT of the image and +y at the top. The ray starts on the near plane
// (tmin = near / d.z for unit d), as Mitsuba's sample_ray does.
//
// Thin lens: the pinhole ray meets the focus plane z = focus_distance at its direction times
// focus_distance. The lens point a = aperture_radius * concentric_disk(u_lens) lies in the z = 0
// plane; the ray goes from a through that focus point (Mitsuba 0.6 and 3 sample_ray). A point at
// depth d off the focus plane f is thus spread over a disk of radius aperture_radius |d - f| / d on
// the focus plane, i.e. aperture_radius |d - f| / (d f) in units of the z = 1 image plane.
//
// Importance (pbrt-v4's PerspectiveCamera::We/PDF_We/SampleWi) is computed in camera space, where
// the film, lens and clip planes have their simple shapes. A uniform scale s in world_from_camera
// leaves angles alone, so cos theta and the film area A (on the plane at distance 1) are the same
// in both spaces; only lens areas are world areas, pi (s r)^2, because the light-transport
// measures (pdf_pos, the area-to-solid-angle conversion in sample_wi) are taken in world space.

// camera.h uses Rgb without including rgb.h (reported to the lead); included first until fixed.
#include "tessera/core/rgb.h"
#include "tessera/render/camera.h"

#include "tessera/core/check.h"
#include "tessera/core/sampling.h"

#include <cmath>

namespace tessera {
namespace {

class PerspectiveCamera final : public Camera {
 public:
  PerspectiveCamera(const Transform& world_from_camera, float fov_x_degrees, int width, int height,
                    float near_clip, float far_clip, float aperture_radius = 0.f, float focus_distance = 1.f)
      : world_from_camera_(world_from_camera), near_(near_clip), far_(far_clip), aperture_(aperture_radius),
        focus_(focus_distance) {
    TESSERA_CHECK(width > 0 && height > 0);
    TESSERA_CHECK(fov_x_degrees > 0.f && fov_x_degrees < 180.f);
    TESSERA_CHECK(aperture_radius >= 0.f && focus_distance > 0.f);
    inv_width_ = 1.f / float(width);
    inv_height_ = 1.f / float(height);
    double aspect = double(width) / double(height);
    tan_half_x_ = float(std::tan(double(fov_x_degrees) * kPi / 360.0));
    tan_half_y_ = float(double(tan_half_x_) / aspect);
    origin_ = world_from_camera_.apply_point(Vec3(0.f));
    camera_from_world_ = world_from_camera_.inverse();
    const Vec3 axis = world_from_camera_.apply_vector(Vec3(0.f, 0.f, 1.f));
    const float scale = length(axis);
    forward_ = axis / scale;
    width_ = float(width);
    height_ = float(height);
    film_area_ = 4.f * tan_half_x_ * tan_half_y_;
    // pbrt's convention: a pinhole's "lens area" is 1, so pdf_pos = 1 for its delta position.
    lens_area_ = aperture_ > 0.f ? kPi * (scale * aperture_) * (scale * aperture_) : 1.f;
  }

  bool has_importance() const override { return true; }

  Rgb we(const Ray& ray, Vec2* raster) const override {
    Vec2 r;
    float cos_theta;
    if (!film_hit(ray, r, cos_theta)) return {};
    if (raster) *raster = r;
    return Rgb(importance(cos_theta));
  }

  void pdf_we(const Ray& ray, float& pdf_pos, float& pdf_dir) const override {
    Vec2 r;
    float cos_theta;
    if (!film_hit(ray, r, cos_theta)) {
      pdf_pos = pdf_dir = 0.f;
      return;
    }
    pdf_pos = 1.f / lens_area_;
    pdf_dir = 1.f / (film_area_ * cos_theta * cos_theta * cos_theta);
  }

  bool sample_wi(Vec3 ref_p, Vec2 u_lens, float /*time*/, CameraSampleWi& out) const override {
    const Vec3 p = camera_from_world_.apply_point(ref_p);
    // generate_ray's rays span camera z in [near, far]: nearer or farther points are not seen.
    if (!(p.z > 0.f && p.z >= near_ && p.z <= far_)) return false;
    const Vec2 lens = aperture_ > 0.f ? square_to_uniform_disk_concentric(u_lens) * aperture_ : Vec2(0.f, 0.f);
    const Vec3 a(lens.x, lens.y, 0.f);
    // generate_ray aims from the lens point at the pinhole ray's point on the focus plane, so the
    // raster is the one whose pinhole ray meets the line a -> p on that plane.
    const float f = focus_plane(), k = f / p.z;
    const Vec2 raster = raster_from_image((a.x + (p.x - a.x) * k) / f, (a.y + (p.y - a.y) * k) / f);
    if (!on_film(raster)) return false;
    out.p_lens = world_from_camera_.apply_point(a);
    const Vec3 to_lens = out.p_lens - ref_p;
    out.dist = length(to_lens);
    if (!(out.dist > 0.f)) return false;
    out.wi = to_lens / out.dist;
    out.n = forward_;
    const float cos_theta = normalize(p - a).z;
    out.we = Rgb(importance(cos_theta));
    out.pdf = out.dist * out.dist / (cos_theta * lens_area_);
    out.raster = raster;
    return true;
  }

  Ray generate_ray(Vec2 raster, Vec2 u_lens) const override {
    float sx = raster.x * inv_width_, sy = raster.y * inv_height_;
    const Vec3 pinhole(tan_half_x_ * (1.f - 2.f * sx), tan_half_y_ * (1.f - 2.f * sy), 1.f);
    Vec3 d_cam, o_world = origin_;
    if (aperture_ > 0.f) {
      const Vec2 lens = square_to_uniform_disk_concentric(u_lens) * aperture_;
      const Vec3 aperture_p(lens.x, lens.y, 0.f);
      d_cam = normalize(pinhole * focus_ - aperture_p);
      o_world = world_from_camera_.apply_point(aperture_p);
    } else {
      d_cam = normalize(pinhole);
    }
    Vec3 d_world = world_from_camera_.apply_vector(d_cam);
    // A to_world with (unsupported but harmless) uniform scale would stretch t: keep distances in
    // camera units by rescaling the clip distances along the normalised world direction.
    float len = length(d_world);
    Ray ray;
    ray.o = o_world;
    ray.d = d_world / len;
    float inv_z = 1.f / d_cam.z;
    ray.tmin = near_ * inv_z * len;
    ray.tmax = far_ * inv_z * len;
    return ray;
  }

 private:
  // Rays through the lens converge on the focus plane; a pinhole's rays can use any plane.
  float focus_plane() const { return aperture_ > 0.f ? focus_ : 1.f; }

  // Inverse of generate_ray's map from raster to the point (px, py, 1) on the image plane.
  Vec2 raster_from_image(float px, float py) const {
    return {0.5f * (1.f - px / tan_half_x_) * width_, 0.5f * (1.f - py / tan_half_y_) * height_};
  }

  // Half-open like the pixels, so a splat never lands in a column or row past the film.
  bool on_film(Vec2 r) const { return r.x >= 0.f && r.x < width_ && r.y >= 0.f && r.y < height_; }

  float importance(float cos_theta) const {
    const float cos2 = cos_theta * cos_theta;
    return 1.f / (film_area_ * lens_area_ * cos2 * cos2);
  }

  // Where `ray` (leaving the lens) crosses the film, and the cosine of its angle to the axis:
  // false when it points backwards or misses the film.
  bool film_hit(const Ray& ray, Vec2& raster, float& cos_theta) const {
    const Vec3 o = camera_from_world_.apply_point(ray.o);
    const Vec3 d = normalize(camera_from_world_.apply_vector(ray.d));
    if (!(d.z > 0.f)) return false;
    cos_theta = d.z;
    const float f = focus_plane();
    const Vec3 q = o + d * ((f - o.z) / d.z);
    raster = raster_from_image(q.x / f, q.y / f);
    return on_film(raster);
  }

  Transform world_from_camera_, camera_from_world_;
  Vec3 origin_, forward_;
  float near_, far_, aperture_, focus_;
  float width_, height_, film_area_, lens_area_;
  float inv_width_, inv_height_;
  float tan_half_x_, tan_half_y_;
};

}  // namespace

std::unique_ptr<Camera> make_perspective_camera(const Transform& world_from_camera, float fov_x_degrees,
                                                int film_width, int film_height, float near_clip,
                                                float far_clip) {
  return std::make_unique<PerspectiveCamera>(world_from_camera, fov_x_degrees, film_width, film_height,
                                             near_clip, far_clip);
}

std::unique_ptr<Camera> make_thinlens_camera(const Transform& world_from_camera, float fov_x_degrees,
                                             int film_width, int film_height, float near_clip, float far_clip,
                                             float aperture_radius, float focus_distance) {
  return std::make_unique<PerspectiveCamera>(world_from_camera, fov_x_degrees, film_width, film_height, near_clip,
                                             far_clip, aperture_radius, focus_distance);
}

}  // namespace tessera
