// The closed-form sphere image against casting a ray through every pixel
// centre and counting those that hit the sphere.
#include "anim/sphere_projection.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <vector>

namespace throng::anim {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Lens {
  double fov_deg;
  int width;
  int height;
  double focal() const { return 0.5 * height / std::tan(0.5 * fov_deg * kPi / 180.0); }
};

// What rays through pixel centres see: count, centroid, second moments.
struct RasterStats {
  double count = 0;
  glm::dvec2 mean{0};
  double cuu = 0, cuv = 0, cvv = 0;  // covariance
};

// samples x samples rays per pixel (1: through the pixel centre); count is in pixels.
RasterStats rasterise(const Lens& lens, glm::dvec3 c, double r, int samples = 1) {
  const double f = lens.focal();
  const double r2 = r * r;
  const double cc = glm::dot(c, c);
  const double step = 1.0 / samples;
  double n = 0, su = 0, sv = 0, suu = 0, suv = 0, svv = 0;
  for (int j = 0; j < lens.height * samples; ++j) {
    const double v = (j + 0.5) * step;
    for (int i = 0; i < lens.width * samples; ++i) {
      const double u = (i + 0.5) * step;
      // Ray from the eye through the sample point (GL camera space).
      const glm::dvec3 dir(u - 0.5 * lens.width, 0.5 * lens.height - v, -f);
      const double dc = glm::dot(dir, c);
      const double dd = glm::dot(dir, dir);
      // Hit when the closest approach of the forward ray is within r.
      const bool hit = dc > 0.0 ? cc - dc * dc / dd <= r2 : cc <= r2;
      if (!hit) continue;
      n += 1;
      su += u;
      sv += v;
      suu += u * u;
      suv += u * v;
      svv += v * v;
    }
  }
  RasterStats s;
  s.count = n * step * step;
  if (n > 0) {
    s.mean = {su / n, sv / n};
    s.cuu = suu / n - s.mean.x * s.mean.x;
    s.cuv = suv / n - s.mean.x * s.mean.y;
    s.cvv = svv / n - s.mean.y * s.mean.y;
  }
  return s;
}

// Camera-space centre of a sphere seen at pixel (u, v) at distance `range` from the eye.
glm::dvec3 centre_at_pixel(const Lens& lens, double u, double v, double range) {
  const glm::dvec3 dir(u - 0.5 * lens.width, 0.5 * lens.height - v, -lens.focal());
  return glm::normalize(dir) * range;
}

bool ellipse_inside_viewport(const ProjectedEllipse<double>& e, const Lens& lens, double margin) {
  const double ca = std::cos(e.angle), sa = std::sin(e.angle);
  const double hu = std::sqrt(e.major * e.major * ca * ca + e.minor * e.minor * sa * sa);
  const double hv = std::sqrt(e.major * e.major * sa * sa + e.minor * e.minor * ca * ca);
  return e.centre.x - hu > margin && e.centre.x + hu < lens.width - margin && e.centre.y - hv > margin &&
         e.centre.y + hv < lens.height - margin;
}

TEST(SphereProjection, AreaWithinTwoPercentOfRasterisedPixelCount) {
  const std::vector<Lens> lenses = {{30, 640, 480}, {60, 640, 480}, {90, 640, 480}, {110, 480, 640}, {50, 1280, 720}};
  // Where on the screen the sphere is seen: centre, on each axis, near each corner.
  const std::vector<glm::dvec2> spots = {{0.50, 0.50}, {0.80, 0.50}, {0.50, 0.15}, {0.15, 0.15},
                                         {0.85, 0.15}, {0.15, 0.85}, {0.88, 0.86}, {0.30, 0.70}};
  // Errors by image size: [400, 2000), [2000, 10000), >= 10000 square pixels.
  double worst[3] = {0, 0, 0}, sum[3] = {0, 0, 0};
  int count[3] = {0, 0, 0};
  int tested = 0;
  for (const Lens& lens : lenses)
    for (const glm::dvec2& spot : spots)
      for (double r : {0.25, 0.6})
        for (double range : {1.2, 3.0, 8.0, 20.0, 50.0}) {
          const glm::dvec3 c = centre_at_pixel(lens, spot.x * lens.width, spot.y * lens.height, range);
          const ProjectedEllipse<double> e =
              project_sphere(c, r, lens.focal(), double(lens.width), double(lens.height));
          ASSERT_EQ(e.kind, SphereImage::Ellipse);
          if (!ellipse_inside_viewport(e, lens, 2.0) || e.area < 400.0) continue;
          const RasterStats s = rasterise(lens, c, r);
          const double rel = std::abs(e.area - s.count) / s.count;
          EXPECT_LT(rel, 0.02) << "fov " << lens.fov_deg << " spot " << spot.x << "," << spot.y << " r " << r
                               << " range " << range << " formula " << e.area << " raster " << s.count;
          const int b = e.area < 2000 ? 0 : (e.area < 10000 ? 1 : 2);
          worst[b] = std::max(worst[b], rel);
          sum[b] += rel;
          ++count[b];
          ++tested;
        }
  EXPECT_GT(tested, 150);
  const char* names[3] = {"[400, 2000)", "[2000, 10000)", ">= 10000"};
  for (int b = 0; b < 3; ++b)
    if (count[b] > 0)
      std::printf("[ sphere area ] %s px: %d cases, |formula - raster| / raster max %.3f%%, mean %.3f%%\n", names[b],
                  count[b], 100 * worst[b], 100 * sum[b] / count[b]);
}

// With many rays per pixel the count converges on the formula: what is
// left at one ray per pixel is sampling error, not a formula error.
TEST(SphereProjection, SupersampledRasterConvergesToTheFormula) {
  const Lens lens{60, 320, 240};
  double worst1 = 0, worst8 = 0;
  for (const glm::dvec2& spot : {glm::dvec2(0.5, 0.5), glm::dvec2(0.2, 0.25), glm::dvec2(0.8, 0.8)})
    for (double range : {6.0, 12.0}) {
      const double r = 0.5;
      const glm::dvec3 c = centre_at_pixel(lens, spot.x * lens.width, spot.y * lens.height, range);
      const auto e = project_sphere(c, r, lens.focal(), double(lens.width), double(lens.height));
      ASSERT_TRUE(ellipse_inside_viewport(e, lens, 2.0));
      const double rel1 = std::abs(rasterise(lens, c, r, 1).count - e.area) / e.area;
      const double rel8 = std::abs(rasterise(lens, c, r, 8).count - e.area) / e.area;
      EXPECT_LT(rel8, 0.003) << "area " << e.area;
      worst1 = std::max(worst1, rel1);
      worst8 = std::max(worst8, rel8);
    }
  std::printf("[ sphere area ] small images (%.0f-%.0f px): max error 1 ray/px %.3f%%, 64 rays/px %.3f%%\n",
              project_sphere(centre_at_pixel(lens, 160, 120, 12.0), 0.5, lens.focal(), 320.0, 240.0).area,
              project_sphere(centre_at_pixel(lens, 160, 120, 6.0), 0.5, lens.focal(), 320.0, 240.0).area, 100 * worst1,
              100 * worst8);
}

TEST(SphereProjection, EllipseCentreAxesAndAngleMatchRasterMoments) {
  const Lens lens{70, 800, 600};
  int tested = 0;
  for (const glm::dvec2& spot :
       {glm::dvec2(0.5, 0.5), glm::dvec2(0.8, 0.25), glm::dvec2(0.2, 0.8), glm::dvec2(0.85, 0.85)})
    for (double range : {3.0, 12.0}) {
      const double r = 0.08 * range;
      const glm::dvec3 c = centre_at_pixel(lens, spot.x * lens.width, spot.y * lens.height, range);
      const auto e = project_sphere(c, r, lens.focal(), double(lens.width), double(lens.height));
      ASSERT_TRUE(ellipse_inside_viewport(e, lens, 2.0));
      const RasterStats s = rasterise(lens, c, r);
      EXPECT_NEAR(s.mean.x, e.centre.x, 0.05 * e.minor);
      EXPECT_NEAR(s.mean.y, e.centre.y, 0.05 * e.minor);
      // A uniform ellipse has covariance R diag(a^2, b^2) R^T / 4.
      const double ca = std::cos(e.angle), sa = std::sin(e.angle);
      const double a2 = e.major * e.major / 4, b2 = e.minor * e.minor / 4;
      const double tol = 0.03 * a2;
      EXPECT_NEAR(s.cuu, a2 * ca * ca + b2 * sa * sa, tol);
      EXPECT_NEAR(s.cuv, (a2 - b2) * ca * sa, tol);
      EXPECT_NEAR(s.cvv, a2 * sa * sa + b2 * ca * ca, tol);
      EXPECT_GE(e.major, e.minor);
      ++tested;
    }
  EXPECT_EQ(tested, 8);
}

// Every point of the ellipse's outline must see the sphere along a tangent ray.
TEST(SphereProjection, OutlineRaysAreTangentToTheSphere) {
  const Lens lens{60, 1000, 1000};
  const double f = lens.focal();
  for (const glm::dvec3 c :
       {glm::dvec3(0.3, -0.2, -4.0), glm::dvec3(2.5, 1.7, -3.0), glm::dvec3(0, 0, -9), glm::dvec3(-7, 4, -5)})
    for (double r : {0.2, 1.0, 2.5}) {
      const auto e = project_sphere(c, r, f, 1000.0, 1000.0);
      ASSERT_EQ(e.kind, SphereImage::Ellipse);
      const glm::dvec2 major(std::cos(e.angle), std::sin(e.angle));
      const glm::dvec2 minor(-major.y, major.x);
      for (int k = 0; k < 36; ++k) {
        const double t = 2 * kPi * k / 36;
        const glm::dvec2 p = e.centre + e.major * std::cos(t) * major + e.minor * std::sin(t) * minor;
        const glm::dvec3 dir = glm::normalize(glm::dvec3(p.x - 500.0, 500.0 - p.y, -f));
        const double along = glm::dot(dir, c);
        EXPECT_GT(along, 0.0);
        const double miss = std::sqrt(std::max(0.0, glm::dot(c, c) - along * along));
        EXPECT_NEAR(miss, r, 1e-9 * (1 + glm::length(c))) << "c " << c.x << "," << c.y << "," << c.z << " r " << r;
      }
    }
}

TEST(SphereProjection, OnAxisSphereIsACircleOfTheTangentConeRadius) {
  const double f = 800.0;
  for (double d : {1.5, 5.0, 50.0})
    for (double r : {0.1, 1.0}) {
      if (r >= d) continue;
      const auto e = project_sphere(glm::dvec3(0, 0, -d), r, f, 1600.0, 1200.0);
      const double radius = f * std::tan(std::asin(r / d));
      EXPECT_NEAR(e.major, radius, 1e-9 * radius);
      EXPECT_NEAR(e.minor, radius, 1e-9 * radius);
      EXPECT_NEAR(e.area, kPi * radius * radius, 1e-9 * e.area);
      EXPECT_NEAR(e.centre.x, 800.0, 1e-9);
      EXPECT_NEAR(e.centre.y, 600.0, 1e-9);
    }
}

TEST(SphereProjection, ClassifiesCameraInsideCrossingAndBehind) {
  SphereImage kind{};
  EXPECT_EQ(sphere_ellipse_area(glm::dvec3(0.1, 0.2, -0.3), 1.0, 500.0, &kind), 0.0);
  EXPECT_EQ(kind, SphereImage::Inside);
  EXPECT_EQ(sphere_ellipse_area(glm::dvec3(3.0, 0.0, -0.5), 1.0, 500.0, &kind), 0.0);
  EXPECT_EQ(kind, SphereImage::Unbounded);
  EXPECT_EQ(sphere_ellipse_area(glm::dvec3(3.0, 0.0, 0.5), 1.0, 500.0, &kind), 0.0);
  EXPECT_EQ(kind, SphereImage::Unbounded);
  EXPECT_EQ(sphere_ellipse_area(glm::dvec3(0.0, 0.0, 2.0), 1.0, 500.0, &kind), 0.0);
  EXPECT_EQ(kind, SphereImage::Behind);
  EXPECT_GT(sphere_ellipse_area(glm::dvec3(0.0, 0.0, -2.0), 1.0, 500.0, &kind), 0.0);
  EXPECT_EQ(kind, SphereImage::Ellipse);
  // The area grows without bound as the sphere nears the camera plane.
  double previous = 0;
  for (double d : {10.0, 3.0, 1.5, 1.1, 1.01, 1.001}) {
    const double a = sphere_ellipse_area(glm::dvec3(0.5, 0.0, -d), 1.0, 500.0);
    EXPECT_GT(a, previous);
    previous = a;
  }
}

TEST(SphereProjection, CoverageClampsToScreenAndCullsOutsideTheFrustum) {
  Camera cam;
  cam.position = {0, 0, 0};
  cam.target = {0, 0, -1};
  cam.width = 640;
  cam.height = 480;
  cam.fov_y = 1.0f;
  const CameraView v = make_camera_view(cam);
  const float screen = 640.0f * 480.0f;
  EXPECT_EQ(sphere_pixel_coverage({0, 0, -0.2f}, 1.0f, v, true), screen);    // inside
  EXPECT_EQ(sphere_pixel_coverage({0.5f, 0, 0.2f}, 1.0f, v, true), screen);  // crossing the camera plane
  EXPECT_EQ(sphere_pixel_coverage({0, 0, 5.0f}, 1.0f, v, true), 0.0f);       // behind
  EXPECT_EQ(sphere_pixel_coverage({0, 0, -1.05f}, 1.0f, v, true), screen);   // huge ellipse, clamped
  const float a = sphere_pixel_coverage({0, 0, -20.0f}, 0.5f, v, true);
  EXPECT_FLOAT_EQ(a, sphere_ellipse_area(glm::vec3(0, 0, -20.0f), 0.5f, v.focal_px));
  // Far to the right of the view: visible only without culling.
  const glm::vec3 right(40.0f, 0.0f, -10.0f);
  EXPECT_EQ(sphere_pixel_coverage(right, 0.5f, v, true), 0.0f);
  EXPECT_GT(sphere_pixel_coverage(right, 0.5f, v, false), 0.0f);
  // Beyond the far plane and nearer than the near plane.
  EXPECT_EQ(sphere_pixel_coverage({0, 0, -2000.0f}, 1.0f, v, true), 0.0f);
  EXPECT_EQ(sphere_pixel_coverage({0, 0, -0.04f}, 0.01f, v, true), 0.0f);
}

// The frustum test never culls a sphere that some pixel centre sees.
TEST(SphereProjection, FrustumCullingIsConservativeAgainstRaster) {
  const Lens lens{60, 160, 120};
  Camera cam;
  cam.position = {0, 0, 0};
  cam.target = {0, 0, -1};
  cam.width = lens.width;
  cam.height = lens.height;
  cam.fov_y = static_cast<float>(lens.fov_deg * kPi / 180.0);
  const CameraView v = make_camera_view(cam);
  int culled = 0, seen = 0;
  for (int i = 0; i < 400; ++i) {
    const double a = 2 * kPi * i / 400.0;
    const glm::dvec3 c(9.0 * std::cos(a), 6.0 * std::sin(3 * a), -6.0 - 4.0 * std::sin(a));
    const double r = 1.0;
    const bool outside = sphere_outside_view(glm::vec3(c), static_cast<float>(r), v);
    const double hits = rasterise(lens, c, r).count;
    if (outside) {
      EXPECT_EQ(hits, 0.0) << i;
      ++culled;
    }
    if (hits > 0) ++seen;
  }
  EXPECT_GT(culled, 50);
  EXPECT_GT(seen, 50);
}

}  // namespace
}  // namespace throng::anim
