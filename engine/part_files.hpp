// `meshstream decimate --part k/K`: the ranges of `--threads K` (ranges.hpp) run as K
// separate jobs, for batch schedulers without MPI (Slurm arrays, Kubernetes indexed jobs). Job k
// (1 .. K-1) decimates range k-1 (run_range) into a part file instead of sending it to rank 0;
// job K/K, the merge, decimates the last range itself, reads the part files' pieces into the
// seam pass in range order (RangesJob::receive_remote) and writes the output: the bytes
// `--threads K` writes with the same options.
//
// A part file (written through io::ByteSink: to a temporary name, renamed into place when
// complete), native byte order (little endian on every platform meshstream builds for):
//
//   header:  magic 89 'M' 'S' 'P' 'A' 'R' 'T' 0A, u32 version (1), u32 header body bytes, body:
//            the build (u32 length + meshstream's version), u32 k, u32 K, the input's size and
//            fingerprint (u64 each), the plan (PartPlan: the decimator's options that change its
//            output, the count the ranges are cut from, the ranges, the attribute weights, the
//            channels carried), u32 bytes of a triangle record, u32 bytes of decimate::Stats
//   pieces:  u8 1, u8 piece (Piece), f64 weight, u64 n, then n io::TriangleRecords (as the MPI
//            ranks send them)
//   end:     u8 2, decimate::Stats (the range's), u8 forced, u64 forced_at, u64 pieces,
//            u64 triangles, u64 hash of every byte from the first piece to here, 'M' 'S' 'P' 'E'
//
// The end has a fixed size, so a part file is checked complete before the merge starts; its
// pieces are read through once then, so that a damaged byte (the hash) is refused before any
// work. Memory: a part file is written and read a chunk at a time (the range's output
// chunks).
#pragma once

#include "decimate/stream_decimator.hpp"
#include "engine/ranges.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace meshstream::io {
class ByteSink;
}

namespace meshstream::engine {

// --part k/K.
struct PartIndex {
    unsigned k = 0, parts = 0;
    bool merge() const { return k == parts; }
};
// Parses "k/K" with 1 <= k <= K and 2 <= K <= 1024; nullopt for anything else.
std::optional<PartIndex> parse_part(const std::string& text);

// What makes two jobs' ranges the same: the decimator's options (ratio the ranges decimate at,
// --target, --buffer, --seed, --weld's size, the sorted axis), the count the input is cut from
// and into how many ranges, the attribute weights (squared, per component: decimate::
// AttributeLayout::omega) and the channels carried.
struct PartPlan {
    decimate::Options options;
    std::optional<uint64_t> target;
    uint64_t cut_triangles = 0;
    unsigned ranges = 0;
    std::vector<double> omega;
    io::Channels channels;
};

// The input file as the parts saw it: its size, and a hash of its first and last 64 KiB and of
// 4 KiB at 14 places between (a part made from another file, or from this one changed since, is
// refused; reading 188 KiB of the file costs nothing beside decimating it). Throws io::Error.
struct InputFingerprint {
    uint64_t size = 0;
    uint64_t hash = 0;
    bool operator==(const InputFingerprint&) const = default;
};
InputFingerprint fingerprint_file(const std::string& path);

// Part k's sink: writes the part file's header when made, then every piece the range makes, and
// at close() its end; the file is renamed into place (commit()) once the range ended normally.
// Throws io::Error when the file cannot be written.
class PartFileSink final : public RangeSink {
public:
    PartFileSink(const std::string& path, PartIndex index, const InputFingerprint& input, const PartPlan& plan);
    ~PartFileSink() override;
    void append(const io::TriangleChunk& chunk, double weight, Piece piece) override;
    void progress(uint64_t decimated) override { decimated_ = decimated; }
    void close(const RangeOutcome& outcome, std::exception_ptr error) override;
    // After close(): the range's exception, or nullptr once the file is in place.
    std::exception_ptr error() const { return error_; }
    uint64_t decimated() const { return decimated_; }
    uint64_t triangles() const { return triangles_; }  // written to the file
    uint64_t bytes() const;                            // of the file

private:
    void put(const void* data, size_t n);
    std::unique_ptr<io::ByteSink> sink_;
    io::TriangleRecords records_;
    std::vector<char> bytes_;
    uint64_t hash_;
    uint64_t pieces_ = 0, triangles_ = 0;
    std::atomic<uint64_t> decimated_{0};
    std::exception_ptr error_;
};

// A part file the merge reads: opened and checked against the merge's plan at once (magic,
// version, build, a complete end, k and K, the input's fingerprint, every setting of the plan),
// every piece read through once (a damaged one is refused here, before any work), its pieces read
// again by feed(). Every error is an io::Error naming the file and what is
// wrong ("part 2/3 was made with --buffer 50000, this job has 400000").
class PartFileReader {
public:
    PartFileReader(const std::string& path, unsigned parts, const InputFingerprint& input, const PartPlan& plan);
    const std::string& path() const { return path_; }
    unsigned k() const { return k_; }
    // The range's outcome and size, from the file's end.
    const RangeOutcome& outcome() const { return outcome_; }
    uint64_t triangles() const { return triangles_; }
    // Puts every piece into `sink` in the file's order, then closes it with the range's outcome;
    // stops between pieces once `stop` is set (the sink is closed then too). Throws io::Error on a
    // piece that is not as written (the sink stays open: the caller closes it with the error).
    void feed(RangeSink& sink, const std::atomic<bool>& stop, const io::Channels& channels) const;

private:
    // Reads the pieces in order, each to `each` (false: stop there, and return false), and checks
    // the hash at the end; true when every piece was read.
    bool read_pieces(
        const std::function<bool(Piece piece, double weight, size_t triangles, const char* records)>& each) const;
    std::string path_;
    unsigned k_ = 0;
    uint64_t header_bytes_ = 0, file_bytes_ = 0;
    RangeOutcome outcome_;
    uint64_t pieces_ = 0, triangles_ = 0, hash_ = 0;
    size_t record_bytes_ = 0;
};

}  // namespace meshstream::engine
