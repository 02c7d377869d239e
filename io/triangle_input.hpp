// The read loop every command shares: it pulls an opened input's chunks, counts the triangles,
// checks the header's promised count at the end, and applies one policy to the triangles no
// consumer may want: those with a NaN or infinite coordinate, and degenerate ones (two corners
// at exactly the same position, -0 = +0). Zero-area triangles with three distinct corners
// (slivers) are never singled out: they are valid geometry.
//
// The policy is the caller's: convert and sort keep every triangle (a format converter does
// not edit geometry unasked), `--clean` and decimate drop them and count them, and `--strict`
// where they would be dropped, or measured (info, compare), makes the first one an error that
// names the file and the triangle's ordinal. Readers still reject malformed input (truncation,
// indices out of range) themselves. Memory: none beyond the caller's chunk.
#pragma once

#include "io/error.hpp"
#include "io/format.hpp"
#include "io/input_count.hpp"

#include <cstdint>
#include <optional>
#include <string>

namespace meshstream::io {

enum class BadTriangles : uint8_t {
    kKeep,    // pass every triangle on, as read
    kDrop,    // drop non-finite and degenerate triangles, counting each kind
    kRefuse,  // throw io::Error at the first one ("triangle 19 has a NaN or infinite coordinate")
};

class TriangleInput {
public:
    // Takes over an opened input. `refuse_note` ends the kRefuse error (by default: strict
    // reading, as a mention: io/error.hpp).
    TriangleInput(Input input, BadTriangles policy, std::string refuse_note = " (" + mention(Setting::kStrict) + ")");
    // The same for a bare reader (no source or format: source() and format() must not be
    // called); `name` names the input in errors.
    TriangleInput(std::unique_ptr<Reader> reader, std::string name, BadTriangles policy,
                  std::string refuse_note = " (" + mention(Setting::kStrict) + ")");

    // Fills `chunk` (cleared first) with the next triangles that pass the policy, at least one,
    // and returns true; returns false at the end of the input, once the header's promised
    // count (if any) was checked against the triangles read. Throws io::Error: the reader's,
    // a broken promise ("header promises N triangles, read M"), or a refused triangle.
    bool next(TriangleChunk& chunk);
    // Before the first next(): reads the triangles [first, end) of the input only, when the
    // reader can go to `first` without reading what comes before (Reader::select_triangles),
    // and returns true; count().read then counts from `first` (refused triangles are named by
    // their ordinal in the file) and the header's promise is checked only by a selection that
    // reaches the end. Returns false, changing nothing, when the reader cannot.
    bool select_triangles(uint64_t first, uint64_t end);

    // For a caller that reads the reader itself (io::IndexedReadAhead, through its IndexedSource):
    // counts the triangles of `chunk`, the reader's next ones, as read and applies the policy
    // to them, as next() does; throws as next() would for a refused triangle.
    void admit(TriangleChunk& chunk);
    // ...and once the reader has no more: the checks next() makes there (the header's promise).
    void end_of_input();

    const InputCount& count() const { return count_; }
    uint64_t non_finite() const { return non_finite_; }  // dropped for a NaN/inf coordinate
    uint64_t degenerate() const { return degenerate_; }  // dropped for a repeated corner
    bool at_end() const { return at_end_; }

    const MeshHeader& header() const { return input_.reader->header(); }
    const std::string& name() const { return name_; }
    const Format& format() const { return *input_.format; }
    ByteSource& source() { return *input_.source; }
    bool has_source() const { return input_.source != nullptr; }  // false for a bare reader
    Reader& reader() { return *input_.reader; }
    // Releases the reader and its source (their buffers and tables) once the loop is done;
    // count(), name() and the drop counts stay; header() and the rest must not be called.
    void close() { input_ = {}; }

private:
    size_t apply_policy(TriangleChunk& chunk);

    Input input_;
    std::string name_;
    BadTriangles policy_;
    std::string refuse_note_;
    InputCount count_;
    uint64_t non_finite_ = 0, degenerate_ = 0;
    bool at_end_ = false;
    std::optional<uint64_t> end_;  // select_triangles()'s end
};

// What the policy looks for in one triangle (9 floats): 0 when it passes, else why not.
enum class TriangleFault : uint8_t { kNone, kNonFinite, kDegenerate };
TriangleFault triangle_fault(const float* xyz);

}  // namespace meshstream::io
