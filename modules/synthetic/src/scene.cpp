// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/scene.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <tuple>
#include <utility>

namespace msf::synthetic {

namespace {
using Float4 = float __attribute__((vector_size(16))); // GCC and Clang vector extensions
} // namespace

std::uint16_t Scene::addMaterial(const Material& material) {
  materials.push_back(material);
  return static_cast<std::uint16_t>(materials.size() - 1);
}

void Scene::buildIndex() {
  const auto n = static_cast<std::int32_t>(primitives.size());
  std::vector<V3> lo(n), hi(n), centroid(n);
  for (std::int32_t i = 0; i < n; ++i) {
    primitives[i].bounds(lo[i], hi[i]);
    centroid[i] = (lo[i] + hi[i]) * 0.5f;
  }
  order_.resize(n);
  for (std::int32_t i = 0; i < n; ++i)
    order_[i] = i;
  nodes_.clear();
  nodes_.reserve(2 * static_cast<std::size_t>(n) + 1);
  if (n > 0)
    build(0, n, lo, hi, centroid);
  children_.assign(nodes_.size(), ChildBoxes{});
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    if (nodes_[i].count > 0)
      continue;
    const Node& l = nodes_[i + 1];
    const Node& r = nodes_[static_cast<std::size_t>(nodes_[i].index)];
    children_[i] = {{l.lo.x, r.lo.x, l.hi.x, r.hi.x}, {l.lo.y, r.lo.y, l.hi.y, r.hi.y}, {l.lo.z, r.lo.z, l.hi.z, r.hi.z}};
  }
}

namespace {
float surfaceArea(V3 lo, V3 hi) {
  const V3 e = hi - lo;
  return 2.f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

constexpr int kSplitBins = 16;

/// The axis and bin (the split lies before it) of the binned surface area heuristic over
/// primitives order[begin, end): the split that minimizes the expected number of primitive
/// tests for a random ray, (area_left n_left + area_right n_right) / area, if one costs less
/// than `leaf_cost`; else axis -1.
std::pair<int, int> bestSplit(const std::vector<std::int32_t>& order, std::int32_t begin, std::int32_t end,
                              const std::vector<V3>& lo, const std::vector<V3>& hi, const std::vector<V3>& centroid,
                              V3 c_lo, V3 c_hi, float leaf_cost) {
  constexpr int kBins = kSplitBins;
  int best_axis = -1, best_bin = 0;
  float best_cost = leaf_cost;
  for (int axis = 0; axis < 3; ++axis) {
    const float extent = c_hi[axis] - c_lo[axis];
    if (extent <= 1e-6f)
      continue;
    V3 bin_lo[kBins], bin_hi[kBins];
    int bin_count[kBins] = {};
    for (int b = 0; b < kBins; ++b) {
      bin_lo[b] = {1e30f, 1e30f, 1e30f};
      bin_hi[b] = {-1e30f, -1e30f, -1e30f};
    }
    for (std::int32_t i = begin; i < end; ++i) {
      const std::int32_t p = order[i];
      const int b = std::min(kBins - 1, static_cast<int>(kBins * (centroid[p][axis] - c_lo[axis]) / extent));
      ++bin_count[b];
      bin_lo[b] = minV(bin_lo[b], lo[p]);
      bin_hi[b] = maxV(bin_hi[b], hi[p]);
    }
    float right_area[kBins];
    int right_count[kBins];
    V3 rl{1e30f, 1e30f, 1e30f}, rh{-1e30f, -1e30f, -1e30f};
    int rc = 0;
    for (int b = kBins - 1; b > 0; --b) {
      rc += bin_count[b];
      if (bin_count[b] > 0) {
        rl = minV(rl, bin_lo[b]);
        rh = maxV(rh, bin_hi[b]);
      }
      right_count[b] = rc;
      right_area[b] = rc > 0 ? surfaceArea(rl, rh) : 0.f;
    }
    V3 ll{1e30f, 1e30f, 1e30f}, lh{-1e30f, -1e30f, -1e30f};
    int lc = 0;
    for (int b = 1; b < kBins; ++b) { // split between bins b - 1 and b
      lc += bin_count[b - 1];
      if (bin_count[b - 1] > 0) {
        ll = minV(ll, bin_lo[b - 1]);
        lh = maxV(lh, bin_hi[b - 1]);
      }
      if (lc == 0 || right_count[b] == 0)
        continue;
      const float cost = static_cast<float>(lc) * surfaceArea(ll, lh) + static_cast<float>(right_count[b]) * right_area[b];
      if (cost < best_cost) {
        best_cost = cost;
        best_axis = axis;
        best_bin = b;
      }
    }
  }
  return {best_axis, best_bin};
}
} // namespace

std::int32_t Scene::build(std::int32_t begin, std::int32_t end, const std::vector<V3>& lo, const std::vector<V3>& hi,
                          const std::vector<V3>& centroid) {
  const auto id = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  V3 box_lo = lo[order_[begin]], box_hi = hi[order_[begin]];
  V3 c_lo = centroid[order_[begin]], c_hi = c_lo;
  for (std::int32_t i = begin; i < end; ++i) {
    box_lo = minV(box_lo, lo[order_[i]]);
    box_hi = maxV(box_hi, hi[order_[i]]);
    c_lo = minV(c_lo, centroid[order_[i]]);
    c_hi = maxV(c_hi, centroid[order_[i]]);
  }
  nodes_[id].lo = box_lo;
  nodes_[id].hi = box_hi;
  const std::int32_t count = end - begin;
  auto makeLeaf = [&] {
    nodes_[id].index = begin;
    nodes_[id].count = static_cast<std::uint16_t>(count);
    return id;
  };
  if (count <= 2)
    return makeLeaf();

  int best_axis, best_bin;
  const float leaf_cost = static_cast<float>(count) * surfaceArea(box_lo, box_hi);
  std::tie(best_axis, best_bin) = bestSplit(order_, begin, end, lo, hi, centroid, c_lo, c_hi, leaf_cost);
  if (best_axis < 0) {
    if (count <= kMaxLeafSize)
      return makeLeaf();
    // No useful split (coincident centroids): halve the list.
    best_axis = 0;
    best_bin = -1;
  }
  std::int32_t mid = (begin + end) / 2;
  if (best_bin >= 0) {
    const float extent = c_hi[best_axis] - c_lo[best_axis];
    const auto it = std::stable_partition(order_.begin() + begin, order_.begin() + end, [&](std::int32_t p) {
      const float offset = centroid[p][best_axis] - c_lo[best_axis];
      return std::min(kSplitBins - 1, static_cast<int>(kSplitBins * offset / extent)) < best_bin;
    });
    mid = static_cast<std::int32_t>(it - order_.begin());
  }
  nodes_[id].axis = static_cast<std::uint16_t>(best_axis);
  build(begin, mid, lo, hi, centroid);
  const std::int32_t right = build(mid, end, lo, hi, centroid);
  nodes_[id].index = right;
  return id;
}

namespace {
/// The ray's hit of the road plane y = ground_y, if nearer than hit.t.
bool intersectGround(const Ray& ray, float ground_y, float tmin, Hit& hit) {
  if (!(ray.dir.y > 0.f))
    return false;
  const float t = (ground_y - ray.origin.y) / ray.dir.y;
  if (!(t > tmin && t < hit.t))
    return false;
  hit.t = t;
  hit.primitive = Hit::kGround;
  hit.face = 3;
  hit.local = ray.origin + ray.dir * t;
  hit.normal = {0.f, -1.f, 0.f};
  return true;
}
} // namespace

void Scene::enterChildren(const ChildBoxes& c, const Ray& ray, const V3& inv, float tmin, float tmax, float entry[2],
                          bool enters[2]) {
  // rayEntersBox for both children in SIMD lanes, the same operations in the same order per
  // lane (so the same results): lanes 0 and 1 are the children's slab distances.
  Float4 t0 = {tmin, tmin, tmin, tmin}, t1 = {tmax, tmax, tmax, tmax};
  auto slab = [&](const float* bounds, float o, float i) {
    Float4 v;
    std::memcpy(&v, bounds, sizeof v);
    const Float4 a = (v - o) * i;
    const Float4 b = __builtin_shufflevector(a, a, 2, 3, 0, 1); // each lane's hi with its lo
    const Float4 near = a < b ? a : b, far = a < b ? b : a;
    t0 = near > t0 ? near : t0;
    t1 = far < t1 ? far : t1;
  };
  slab(c.x, ray.origin.x, inv.x);
  slab(c.y, ray.origin.y, inv.y);
  slab(c.z, ray.origin.z, inv.z);
  for (int k = 0; k < 2; ++k) {
    entry[k] = t0[k];
    enters[k] = t0[k] <= t1[k];
  }
}

bool Scene::intersect(const Ray& ray, float tmin, float tmax, Hit& hit) const {
  hit = Hit();
  hit.t = tmax;
  bool found = intersectGround(ray, layout.ground_y, tmin, hit);
  float entry = 0.f;
  if (nodes_.empty() || !rayEntersBox(nodes_[0].lo, nodes_[0].hi, ray.origin,
                                      {1.f / ray.dir.x, 1.f / ray.dir.y, 1.f / ray.dir.z}, tmin, hit.t, entry))
    return found;
  const V3 inv{1.f / ray.dir.x, 1.f / ray.dir.y, 1.f / ray.dir.z};
  // Nodes whose box the ray enters, with the entry distance: a node is skipped when a hit
  // found meanwhile lies before it; of two children the nearer is visited first. Node and
  // distance in two arrays: an {int, float} pair written as two 4-byte stores and read back as
  // one 8-byte load missed the store forwarding, a quarter of the renderer's time.
  std::int32_t stack_node[64];
  float stack_t[64];
  int top = 0;
  auto push = [&](std::int32_t node, float t) {
    stack_node[top] = node;
    stack_t[top++] = t;
  };
  push(0, entry);
  while (top > 0) {
    --top;
    const std::int32_t current = stack_node[top];
    if (stack_t[top] > hit.t)
      continue;
    const Node& node = nodes_[static_cast<std::size_t>(current)];
    if (node.count > 0) {
      for (std::int32_t i = node.index; i < node.index + node.count; ++i) {
        const std::int32_t p = order_[static_cast<std::size_t>(i)];
        if (primitives[static_cast<std::size_t>(p)].intersect(ray, tmin, hit)) {
          hit.primitive = p;
          found = true;
        }
      }
      continue;
    }
    const std::int32_t left = current + 1, right = node.index;
    float entry_of[2];
    bool enters[2];
    enterChildren(children_[static_cast<std::size_t>(current)], ray, inv, tmin, hit.t, entry_of, enters);
    const float t_left = entry_of[0], t_right = entry_of[1];
    const bool hit_left = enters[0], hit_right = enters[1];
    if (hit_left && hit_right) {
      if (t_left <= t_right) {
        push(right, t_right);
        push(left, t_left);
      } else {
        push(left, t_left);
        push(right, t_right);
      }
    } else if (hit_left) {
      push(left, t_left);
    } else if (hit_right) {
      push(right, t_right);
    }
  }
  return found;
}

bool Scene::occupied(V3 p, float inset, std::int32_t skip) const {
  if (p.y > layout.ground_y + inset)
    return true;
  if (nodes_.empty())
    return false;
  std::int32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (p.x < node.lo.x || p.y < node.lo.y || p.z < node.lo.z || p.x > node.hi.x || p.y > node.hi.y ||
        p.z > node.hi.z)
      continue;
    if (node.count > 0) {
      for (std::int32_t i = node.index; i < node.index + node.count; ++i)
        if (order_[i] != skip && primitives[order_[i]].contains(p, inset))
          return true;
      continue;
    }
    stack[top++] = node.index;
    stack[top++] = static_cast<std::int32_t>(&node - nodes_.data()) + 1;
  }
  return false;
}

std::uint32_t Scene::objectCount() const {
  std::uint32_t n = 0;
  for (const auto& p : primitives)
    n = std::max(n, p.object);
  for (const auto& m : movers)
    n = std::max(n, m.object());
  return n;
}

} // namespace msf::synthetic
