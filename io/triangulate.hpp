// Polygon triangulation for the indexed readers (PLY, OBJ), which read faces of any corner
// count: the fan for convex polygons, ear clipping for the others, so a concave face becomes
// triangles that cover it once instead of a fan that folds over itself.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace meshstream::io {

// Working memory of triangulate_polygon, kept by the caller and reused from polygon to polygon.
struct TriangulateScratch {
    std::vector<double> uv;            // corners projected to the polygon's plane
    std::vector<uint32_t> prev, next;  // the remaining ring
    std::vector<uint8_t> reflex, listed, ear;
    std::vector<uint32_t> reflex_list;  // may still hold corners that have stopped being reflex
    std::vector<uint32_t> ears;         // candidates to clip; entries whose ear flag is unset are stale
};

// Triangulates the polygon with corners xyz[3k .. 3k+2], k < n = xyz.size() / 3 (3 <= n < 2^32),
// appending exactly n - 2 triangles to `triangles` as corner numbers (3 a triangle) in the
// polygon's orientation. A convex polygon gives the fan (0, k, k+1), k = 1 .. n-2, in that
// order. Any other is ear-clipped in the plane of its Newell normal, which is exact for simple
// (non-self-intersecting) polygons, including a hole joined to the outline by a doubled edge;
// when no ear is left (self-intersecting or degenerate input) the rest is fanned, so the count
// holds for every input. Time O(n) when convex, else O(n r) for r reflex corners; scratch
// about 50 bytes a corner.
void triangulate_polygon(std::span<const float> xyz, TriangulateScratch& scratch, std::vector<uint32_t>& triangles);

}  // namespace meshstream::io
