// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/synthetic/counter_rng.h>
#include <msf/synthetic/primitive.h>
#include <msf/synthetic/scene.h>

#include <cstdint>
#include <vector>

namespace msf::synthetic {

/// A car's size and paint: what parked and moving cars draw alike.
struct CarLook {
  float length_m = 4.3f;
  float width_m = 1.8f;
  std::uint16_t body = 0;  ///< CarPaint material in the scene
  std::uint16_t cabin = 0; ///< CarCabin material, the same paint
};

/// Draws a car's length, width and paint from `rng`, then one pattern seed for its body and
/// one for its cabin, in that order (the parked cars' stream depends on it), and adds the
/// two materials to `scene`.
CarLook drawCarLook(SequentialRng& rng, Scene& scene);

/// A car's solids in its own frame (origin on the road under its centre, x right, y down,
/// +z its front): body and cabin boxes and four tyres, all with instance id `object`.
/// Place them with Primitive::placed.
std::vector<Primitive> carSolids(const CarLook& car, std::uint16_t tyre, std::uint32_t object);

} // namespace msf::synthetic
