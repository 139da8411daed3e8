#include "anim/sphere_projection.h"

namespace throng::anim {

const char* to_string(SphereImage kind) {
  switch (kind) {
    case SphereImage::Behind: return "behind";
    case SphereImage::Ellipse: return "ellipse";
    case SphereImage::Unbounded: return "unbounded";
    case SphereImage::Inside: return "inside";
  }
  return "unknown";
}

}  // namespace throng::anim
