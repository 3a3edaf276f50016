// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/car.h>

namespace msf::synthetic {

CarLook drawCarLook(SequentialRng& rng, Scene& scene) {
  struct Paint {
    float r, g, b;
  };
  static const Paint kPaint[] = {{0.70f, 0.70f, 0.70f}, {0.45f, 0.46f, 0.48f}, {0.04f, 0.04f, 0.045f},
                                 {0.12f, 0.12f, 0.13f}, {0.05f, 0.08f, 0.20f}, {0.45f, 0.05f, 0.04f},
                                 {0.10f, 0.20f, 0.45f}, {0.50f, 0.45f, 0.35f}};
  CarLook car;
  car.length_m = static_cast<float>(rng.uniform(3.9, 4.8));
  car.width_m = static_cast<float>(rng.uniform(1.7, 1.85));
  const Paint paint = kPaint[rng.index(8)];
  car.body = scene.addMaterial({MaterialType::CarPaint, paint.r, paint.g, paint.b, rng.seed32(), 0.3f});
  car.cabin = scene.addMaterial({MaterialType::CarCabin, paint.r, paint.g, paint.b, rng.seed32(), 0.1f});
  return car;
}

std::vector<Primitive> carSolids(const CarLook& car, std::uint16_t tyre, std::uint32_t object) {
  const float length = car.length_m, width = car.width_m;
  // y points down: a point `height` above the road is at -height.
  std::vector<Primitive> solids{
      boxSolid({0.f, -0.615f, 0.f}, {0.5f * width, 0.335f, 0.5f * length}, car.body, 0.f, object),
      boxSolid({0.f, -1.19f, -0.06f * length}, {0.43f * width, 0.24f, 0.27f * length}, car.cabin, 0.f, object)};
  for (const float x : {-0.5f * width + 0.13f, 0.5f * width - 0.13f})
    for (const float z : {-0.5f * length + 0.85f, 0.5f * length - 0.85f})
      solids.push_back(cylinderSolid({x, -0.31f, z}, 0, 0.31f, 0.1f, tyre, 0.f, object));
  return solids;
}

} // namespace msf::synthetic
