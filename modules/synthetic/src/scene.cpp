#include <msf/common/exceptions.h>
#include <msf/synthetic/scene.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>

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
  wide_.clear();
  leaves_.clear();
  if (n == 0)
    return;
  parent_.assign(nodes_.size(), -1);
  position_.assign(static_cast<std::size_t>(n), 0);
  leaf_.assign(static_cast<std::size_t>(n), 0);
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const Node& node = nodes_[i];
    if (node.count > 0) {
      for (std::int32_t k = node.index; k < node.index + node.count; ++k) {
        position_[static_cast<std::size_t>(order_[static_cast<std::size_t>(k)])] = k;
        leaf_[static_cast<std::size_t>(order_[static_cast<std::size_t>(k)])] = static_cast<std::int32_t>(i);
      }
    } else {
      parent_[i + 1] = static_cast<std::int32_t>(i);
      parent_[static_cast<std::size_t>(node.index)] = static_cast<std::int32_t>(i);
    }
  }
  collapse(0); // the root is wide_[0]
  // A visit pushes at most 4 and pops 1: the stack holds 3 per level and the root.
  std::function<int(std::int32_t)> depth = [&](std::int32_t i) {
    int below = 0;
    const WideNode& node = wide_[static_cast<std::size_t>(i)];
    for (int k = 0; k < node.count; ++k)
      if (node.child[k] >= 0)
        below = std::max(below, depth(node.child[k]));
    return below + 1;
  };
  if (3 * depth(0) + 1 > kStackSize)
    throw InvalidInputError("scene hierarchy too deep for the ray caster's stack (" + std::to_string(depth(0)) +
                            " levels)");
}

namespace {
float surfaceArea(V3 lo, V3 hi) {
  const V3 e = hi - lo;
  return 2.f * (e.x * e.y + e.y * e.z + e.z * e.x);
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

  // Binned surface area heuristic: the split that minimizes the expected number of
  // primitive tests for a random ray, (area_left n_left + area_right n_right) / area.
  constexpr int kBins = 16;
  int best_axis = -1, best_bin = 0;
  float best_cost = static_cast<float>(count) * surfaceArea(box_lo, box_hi);
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
      const std::int32_t p = order_[i];
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
      return std::min(kBins - 1, static_cast<int>(kBins * (centroid[p][best_axis] - c_lo[best_axis]) / extent)) < best_bin;
    });
    mid = static_cast<std::int32_t>(it - order_.begin());
  }
  nodes_[id].axis = static_cast<std::uint16_t>(best_axis);
  build(begin, mid, lo, hi, centroid);
  const std::int32_t right = build(mid, end, lo, hi, centroid);
  nodes_[id].index = right;
  return id;
}

std::int32_t Scene::collapse(std::int32_t binary) {
  // The children: the binary node's two, then the inner one of largest area split into its
  // two while there are fewer than 4 (a leaf root is a node with one leaf child).
  std::int32_t kids[4] = {binary, 0, 0, 0};
  int count = 1;
  if (nodes_[static_cast<std::size_t>(binary)].count == 0) {
    kids[0] = binary + 1;
    kids[1] = nodes_[static_cast<std::size_t>(binary)].index;
    count = 2;
  }
  while (count < 4) {
    int widest = -1;
    float widest_area = -1.f;
    for (int k = 0; k < count; ++k) {
      const Node& node = nodes_[static_cast<std::size_t>(kids[k])];
      const float area = surfaceArea(node.lo, node.hi);
      if (node.count == 0 && area > widest_area) {
        widest = k;
        widest_area = area;
      }
    }
    if (widest < 0)
      break;
    const std::int32_t split = kids[widest];
    kids[widest] = split + 1;
    kids[count++] = nodes_[static_cast<std::size_t>(split)].index;
  }
  const auto id = static_cast<std::int32_t>(wide_.size());
  wide_.emplace_back();
  for (int k = 0; k < 4; ++k) { // lanes past count repeat the first child, never read
    const Node& node = nodes_[static_cast<std::size_t>(kids[k < count ? k : 0])];
    WideNode& w = wide_[static_cast<std::size_t>(id)];
    w.lo_x[k] = node.lo.x;
    w.lo_y[k] = node.lo.y;
    w.lo_z[k] = node.lo.z;
    w.hi_x[k] = node.hi.x;
    w.hi_y[k] = node.hi.y;
    w.hi_z[k] = node.hi.z;
  }
  wide_[static_cast<std::size_t>(id)].count = count;
  for (int k = 0; k < count; ++k) {
    const Node& node = nodes_[static_cast<std::size_t>(kids[k])];
    std::int32_t child;
    if (node.count > 0) {
      child = ~static_cast<std::int32_t>(leaves_.size());
      leaves_.push_back({node.index, node.count});
    } else {
      child = collapse(kids[k]); // grows wide_: index it afresh
    }
    wide_[static_cast<std::size_t>(id)].child[k] = child;
  }
  return id;
}

bool Scene::metBefore(std::int32_t p, std::int32_t q, const Ray& ray, float tmin) const {
  const std::int32_t pos_p = position_[static_cast<std::size_t>(p)], pos_q = position_[static_cast<std::size_t>(q)];
  // Each solid's path from the root to its leaf, and where the two part.
  auto path = [&](std::int32_t solid) {
    std::vector<std::int32_t> nodes;
    for (std::int32_t i = leaf_[static_cast<std::size_t>(solid)]; i >= 0; i = parent_[static_cast<std::size_t>(i)])
      nodes.push_back(i);
    std::reverse(nodes.begin(), nodes.end());
    return nodes;
  };
  const std::vector<std::int32_t> a = path(p), b = path(q);
  std::size_t k = 0;
  while (k < a.size() && k < b.size() && a[k] == b[k])
    ++k;
  if (k == a.size() || k == b.size()) // the same leaf
    return pos_p < pos_q;
  const Node& parting = nodes_[static_cast<std::size_t>(a[k - 1])];
  const Node &left = nodes_[static_cast<std::size_t>(a[k - 1]) + 1], &right = nodes_[static_cast<std::size_t>(parting.index)];
  const V3 inv{1.f / ray.dir.x, 1.f / ray.dir.y, 1.f / ray.dir.z};
  const float far = std::numeric_limits<float>::infinity();
  float entry_left = 0.f, entry_right = 0.f;
  rayEntersBox(left.lo, left.hi, ray.origin, inv, tmin, far, entry_left);
  rayEntersBox(right.lo, right.hi, ray.origin, inv, tmin, far, entry_right);
  return (a[k] == a[k - 1] + 1) == (entry_left <= entry_right);
}

inline bool Scene::test(std::int32_t p, const Ray& ray, float tmin, Hit& hit) const {
  // Primitive::intersect takes only t < hit.t: it is asked for t <= hit.t, and a tie is
  // then settled by the binary traversal's order (the road plane, tested first, wins).
  const Hit before = hit;
  hit.t = std::nextafter(before.t, std::numeric_limits<float>::infinity());
  if (!primitives[static_cast<std::size_t>(p)].intersect(ray, tmin, hit)) {
    hit.t = before.t;
    return false;
  }
  if (hit.t == before.t && (before.primitive < 0 || !metBefore(p, before.primitive, ray, tmin))) {
    hit = before;
    return false;
  }
  hit.primitive = p;
  return true;
}

bool Scene::intersect(const Ray& ray, float tmin, float tmax, Hit& hit) const {
  hit = Hit();
  hit.t = tmax;
  bool found = false;
  if (ray.dir.y > 0.f) {
    const float t = (layout.ground_y - ray.origin.y) / ray.dir.y;
    if (t > tmin && t < hit.t) {
      hit.t = t;
      hit.primitive = Hit::kGround;
      hit.face = 3;
      hit.local = ray.origin + ray.dir * t;
      hit.normal = {0.f, -1.f, 0.f};
      found = true;
    }
  }
  if (wide_.empty())
    return found;
  const V3 inv{1.f / ray.dir.x, 1.f / ray.dir.y, 1.f / ray.dir.z};
  // Nodes and leaves whose box the ray enters, with the entry distance: one is skipped when a
  // hit found meanwhile lies before it; the nearest is visited first. Node and distance in
  // two arrays: an {int, float} pair written as two 4-byte stores and read back as one 8-byte
  // load missed the store forwarding.
  std::int32_t stack_node[kStackSize];
  float stack_t[kStackSize];
  int top = 0;
  stack_node[top] = 0;
  stack_t[top++] = tmin;
  const Float4 origin_x = {ray.origin.x, ray.origin.x, ray.origin.x, ray.origin.x};
  const Float4 origin_y = {ray.origin.y, ray.origin.y, ray.origin.y, ray.origin.y};
  const Float4 origin_z = {ray.origin.z, ray.origin.z, ray.origin.z, ray.origin.z};
  const Float4 inv_x = {inv.x, inv.x, inv.x, inv.x}, inv_y = {inv.y, inv.y, inv.y, inv.y};
  const Float4 inv_z = {inv.z, inv.z, inv.z, inv.z};
  while (top > 0) {
    --top;
    const std::int32_t current = stack_node[top];
    if (stack_t[top] > hit.t)
      continue;
    if (current < 0) {
      const Leaf& leaf = leaves_[static_cast<std::size_t>(~current)];
      for (std::int32_t i = leaf.first; i < leaf.first + leaf.count; ++i)
        found |= test(order_[static_cast<std::size_t>(i)], ray, tmin, hit);
      continue;
    }
    // rayEntersBox for the 4 children in SIMD lanes, the same operations per lane.
    const WideNode& node = wide_[static_cast<std::size_t>(current)];
    Float4 t0 = {tmin, tmin, tmin, tmin}, t1 = {hit.t, hit.t, hit.t, hit.t};
    auto slab = [&](const float* lo, const float* hi, Float4 o, Float4 i) {
      Float4 l, h;
      std::memcpy(&l, lo, sizeof l);
      std::memcpy(&h, hi, sizeof h);
      const Float4 a = (l - o) * i, b = (h - o) * i;
      const Float4 near = a < b ? a : b, far = a < b ? b : a;
      t0 = near > t0 ? near : t0;
      t1 = far < t1 ? far : t1;
    };
    slab(node.lo_x, node.hi_x, origin_x, inv_x);
    slab(node.lo_y, node.hi_y, origin_y, inv_y);
    slab(node.lo_z, node.hi_z, origin_z, inv_z);
    // The children entered, inserted above the stack's top by entry, farthest lowest, so the
    // nearest pops next.
    const int base = top;
    for (int k = 0; k < node.count; ++k) {
      if (!(t0[k] <= t1[k]))
        continue;
      int j = top++;
      for (; j > base && stack_t[j - 1] < t0[k]; --j) {
        stack_node[j] = stack_node[j - 1];
        stack_t[j] = stack_t[j - 1];
      }
      stack_node[j] = node.child[k];
      stack_t[j] = t0[k];
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
