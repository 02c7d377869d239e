// TriangleInput: see triangle_input.hpp for the policy.
#include "io/triangle_input.hpp"

#include "io/error.hpp"

#include <cmath>

namespace meshstream::io {
namespace {

bool same_point(const float* a, const float* b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

}  // namespace

TriangleFault triangle_fault(const float* t) {
    bool finite = true;
    for (int k = 0; k < 9; ++k) finite &= std::isfinite(t[k]);
    if (!finite) return TriangleFault::kNonFinite;
    // Float ==, so -0 and +0 are one position, as the welders see them.
    if (same_point(t, t + 3) || same_point(t + 3, t + 6) || same_point(t, t + 6)) return TriangleFault::kDegenerate;
    return TriangleFault::kNone;
}

TriangleInput::TriangleInput(Input input, BadTriangles policy, std::string refuse_note)
    : input_(std::move(input)), name_(input_.source->name()), policy_(policy), refuse_note_(std::move(refuse_note)) {
    count_.promised = input_.reader->header().triangle_count;
}

TriangleInput::TriangleInput(std::unique_ptr<Reader> reader, std::string name, BadTriangles policy,
                             std::string refuse_note)
    : name_(std::move(name)), policy_(policy), refuse_note_(std::move(refuse_note)) {
    input_.reader = std::move(reader);
    count_.promised = input_.reader->header().triangle_count;
}

bool TriangleInput::next(TriangleChunk& chunk) {
    if (at_end_) {
        chunk.clear();
        return false;
    }
    for (;;) {
        if (!input_.reader->next(chunk)) {
            end_of_input();
            return false;
        }
        admit(chunk);
        if (!chunk.empty()) return true;
    }
}

void TriangleInput::admit(TriangleChunk& chunk) {
    const size_t read = chunk.size();
    const size_t dropped = policy_ == BadTriangles::kKeep ? 0 : apply_policy(chunk);
    count_.read += read;
    count_.dropped += dropped;
}

void TriangleInput::end_of_input() {
    at_end_ = true;
    if (end_ && count_.read != *end_)
        throw Error(name(), "the input ends at triangle " + std::to_string(count_.read) +
                                ", before the end of the triangles read, " + std::to_string(*end_));
    if (!end_ && count_.promised && count_.read != *count_.promised)
        throw Error(name(), "header promises " + std::to_string(*count_.promised) + " triangles, read " +
                                std::to_string(count_.read));
}

bool TriangleInput::select_triangles(uint64_t first, uint64_t end) {
    if (at_end_ || count_.read > 0 || !input_.reader->select_triangles(first, end)) return false;
    count_.read = first;
    end_ = end;
    return true;
}

size_t TriangleInput::apply_policy(TriangleChunk& chunk) {
    const size_t n = chunk.size();
    const float* xyz = chunk.xyz_storage();
    size_t kept = 0;
    for (size_t i = 0; i < n; ++i) {
        const TriangleFault fault = triangle_fault(xyz + 9 * i);
        if (fault != TriangleFault::kNone) {
            if (policy_ == BadTriangles::kRefuse)
                throw Error(name(), "triangle " + std::to_string(count_.read + i + 1) +
                                        (fault == TriangleFault::kDegenerate
                                             ? " is degenerate (two corners at the same position)"
                                             : " has a NaN or infinite coordinate") +
                                        refuse_note_);
            ++(fault == TriangleFault::kDegenerate ? degenerate_ : non_finite_);
            continue;
        }
        if (kept != i) chunk.copy_triangle(kept, chunk, i);
        ++kept;
    }
    chunk.resize(kept);
    return n - kept;
}

}  // namespace meshstream::io
