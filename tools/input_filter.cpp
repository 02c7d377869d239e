// TriangleFilter: see input_filter.hpp for the policy.
#include "tools/input_filter.hpp"

#include "io/error.hpp"

#include <cmath>
#include <cstring>

namespace meshstream::tools {
namespace {

bool same_point(const float* a, const float* b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

}  // namespace

size_t TriangleFilter::apply(io::TriangleChunk& chunk) {
    const size_t n = chunk.size();
    float* xyz = chunk.xyz_storage();
    size_t kept = 0;
    for (size_t i = 0; i < n; ++i, ++seen_) {
        const float* t = xyz + 9 * i;
        bool finite = true;
        for (int k = 0; k < 9; ++k) finite &= std::isfinite(t[k]);
        const bool degenerate = finite && (same_point(t, t + 3) || same_point(t + 3, t + 6) || same_point(t, t + 6));
        if (!finite || degenerate) {
            if (strict_)
                throw io::Error(file_, "triangle " + std::to_string(seen_ + 1) +
                                           (finite ? " is degenerate (two corners at the same position)"
                                                   : " has a NaN or infinite coordinate") +
                                           " (--strict)");
            ++(finite ? degenerate_ : non_finite_);
            continue;
        }
        if (kept != i) chunk.copy_triangle(kept, chunk, i);
        ++kept;
    }
    chunk.resize(kept);
    return n - kept;
}

void TriangleFilter::report(Warnings& warnings) const {
    if (seen_ == 0) warnings.note("the input holds no triangles");
    if (non_finite_ > 0) warnings.add("triangles with a NaN or infinite coordinate skipped", non_finite_);
    if (degenerate_ > 0) warnings.add("degenerate triangles (two corners at the same position) skipped", degenerate_);
}

}  // namespace meshstream::tools
