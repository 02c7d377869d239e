// The READ / DECIMATE / WRITE schedule of Wu & Kobbelt 2003, §4.1, in closed form.
//
// Each triangle written statistically stands for 1/p input triangles, so the N_current
// in-core triangles stand for N_in − N_out/p input triangles and the in-core resolution is
// R = N_current / (N_in − N_out/p). WRITE is allowed only once R has come down to p, i.e.
// once N_current ≤ p·N_in − N_out (the "budget"); writing k triangles lowers N_current and
// the budget alike, so it keeps R. With hysteresis the buffer is only worked on when it is
// full:
//   decimate to max(N_max/2, budget), then write down to N_max/2.
// While the budget is below N_max/2 this is the initialization loop (READ N_max/2,
// DECIMATE N_max/4, no writes, R falls towards p); afterwards it is the main loop (READ
// N_max/2, DECIMATE (1−p)·N_max/4, WRITE p·N_max/2). The final loop decimates to
// round(p·N_in) − N_out and writes everything. None of it needs N_in in advance.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace meshstream::decimate {

// Triangles the in-core portion may hold at resolution p: p·N_in − N_out (may be negative
// when earlier writes were forced).
inline double resolution_budget(double ratio, uint64_t triangles_in, uint64_t triangles_out) {
    return ratio * double(triangles_in) - double(triangles_out);
}

// The in-core resolution level R of §4.1 (infinity before anything stands for input).
inline double resolution_level(double ratio, size_t current, uint64_t triangles_in, uint64_t triangles_out) {
    const double represented = double(triangles_in) - double(triangles_out) / ratio;
    return represented > 0 ? double(current) / represented : INFINITY;
}

// The budget of a decimator that is one part of a mesh cut into ranges (parallel decimation):
// faces with a corner on P_in cannot be decimated yet and stand for themselves, at full
// resolution, so the other in-core faces are held at p: N_current − pinned ≤
// p·(represented − N_out/p − pinned). `represented` counts the input triangles read, each
// weighted by how many input triangles it stands for (1 for the input itself).
inline double part_budget(double ratio, double represented, uint64_t triangles_out, size_t pinned) {
    return ratio * represented - double(triangles_out) + (1 - ratio) * double(pinned);
}

// The budget a range ends with (StreamDecimator::finish_range): part_budget, but the faces on
// P_in count only for what the seam pass will not remove. Every vertex still on P_in at the
// range's end is on a seam (or a hole's rim); the seam pass joins the seam and collapses each of
// its vertices away, removing one face on each side, which leaves the strip at the ratio. So the
// faces on P_in stand for one face a vertex on P_in, not for (1 − p) of themselves: the range
// decimates the difference itself, by its own quadrics, instead of leaving it to the seam pass,
// whose quadrics of the ranges' decimated interiors hold only the planes of the decimated
// triangles. Never above part_budget.
inline double range_end_budget(double ratio, double represented, uint64_t triangles_out, size_t pinned,
                               size_t open_vertices) {
    return ratio * represented - double(triangles_out) + std::min((1 - ratio) * double(pinned), double(open_vertices));
}

struct RoomPlan {
    size_t decimate_to;  // collapse until the buffer holds at most this many triangles
    size_t write_to;     // then write until it holds at most this many
};

// What to do when the buffer of `capacity` triangles is full (hysteresis: refill to 100 %,
// work down to 50 %).
inline RoomPlan plan_full_buffer(size_t capacity, double budget) {
    const size_t half = capacity / 2;
    const size_t decimate_to =
        budget <= double(half) ? half : std::min(capacity, static_cast<size_t>(std::ceil(budget)));
    return {decimate_to, half};
}

inline RoomPlan plan_full_buffer(size_t capacity, double ratio, uint64_t triangles_in, uint64_t triangles_out) {
    return plan_full_buffer(capacity, resolution_budget(ratio, triangles_in, triangles_out));
}

// The exact output size: round(p·N_in), or the explicit target.
inline uint64_t final_triangle_count(double ratio, uint64_t triangles_in) {
    return static_cast<uint64_t>(std::llround(ratio * double(triangles_in)));
}

// In-core triangles to keep for the final WRITE so that the output totals `target`.
inline size_t final_budget(uint64_t target, uint64_t triangles_out) {
    return target > triangles_out ? static_cast<size_t>(target - triangles_out) : 0;
}

}  // namespace meshstream::decimate
