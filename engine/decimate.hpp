// One call per decimation job: a file or a stream decimated as `meshstream decimate` does it,
// by a library user. Between any reader and writer of the registry: the channels the output can
// hold carried through (decimate::AttributeLayout), the memory split between the reader, the
// sort and the writer, a first pass that counts the input when a target or the ranges need a
// count its header does not state, the input cut into ranges decimated on every core with the
// seam pass (engine/ranges.hpp), the ranges of separate jobs (part files, engine/part_files.hpp)
// or of MPI ranks (RangeProcesses), and sorting on demand:
//
// SortPolicy::kAuto: input not known to be sorted is decimated as it comes until the first
// forced write, the sign that it is in no streaming order the buffer can hold. Then the attempt
// is dropped (a file output's temporary file, or the output held back for a pipe), the input is
// sorted out of core (sort/external_sort.hpp, within half of the memory budget, runs in the
// temporary directory), from the file again or from a spool of stdin written meanwhile, and the
// sorted stream is decimated. Input in streaming order costs nothing extra; kAlways sorts first,
// kNever never.
//
// Memory: the decimators' buffers (DecimateSettings::buffer triangles each, about 580 bytes a
// triangle; one per range and a quarter of one for the seam pass) plus what the two formats need
// within the memory budgets of ReadOptions and WriteOptions; the output streams while the input
// is still being read.
//
// Errors: io::Error for what cannot be read or written (file and position), io::OptionError for
// settings that cannot work with this input (its setting() says which), Cancelled once the
// ProgressSink says so. Nothing is left of an output that was not completed.
#pragma once

#include "decimate/stream_decimator.hpp"
#include "engine/part_files.hpp"
#include "engine/progress.hpp"
#include "engine/ranges.hpp"
#include "engine/warnings.hpp"
#include "io/format.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace meshstream::engine {

enum class SortPolicy : uint8_t {
    kAuto,    // sort when the input's order calls for it (see above)
    kAlways,  // sort first
    kNever,   // decimate as read
};

// A weld of corners closer than a grid step: `size` in the model's units, or, with
// `of_diagonal`, in percent of the input's bounding-box diagonal (found in a first pass over
// the input, which must then be a file).
struct Weld {
    double size = 0;
    bool of_diagonal = false;
};

struct DecimateSettings {
    std::string input;   // a path, or "-" for stdin
    std::string output;  // a path, or "-" for stdout
    // The input's format by its registry name; empty: detected (magic bytes, then extension).
    std::string input_format;
    // The output's format by its registry name (io::find_format); empty: from the output's
    // extension. A part job (part.k < part.parts) writes a part file: this names the format of the
    // merge's output, which decides the channels carried (empty: meshstream's triangle stream,
    // which keeps every channel).
    std::string output_format;

    // The output's size: `target` triangles exactly, else round(`ratio` · input); neither:
    // ratio 0.1.
    std::optional<double> ratio;
    std::optional<uint64_t> target;
    size_t buffer = decimate::kDefaultBufferTriangles;  // triangles: fixes the memory
    Weld weld;
    // The axis the input is sorted along, when the caller knows better than the file.
    std::optional<int> sorted_axis;
    SortPolicy sort = SortPolicy::kAuto;
    // Ranges decimated at once (1: one stream decimator); an input of fewer than 2·buffer
    // triangles, a stream, or SortPolicy::kAlways is decimated by one.
    unsigned threads = 1;
    decimate::AttributeWeights weights;
    uint64_t seed = 1;

    // The reader's options: its memory budget (the sort gets half, its reader a quarter), the
    // temporary directory, strict reading, and the channel kinds to read at all.
    io::ReadOptions read;
    // The writer's options (memory budget, format options); channels and materials are set by
    // the job.
    io::WriteOptions write;
    int gzip_level = 6;  // for an output named *.gz

    // Part jobs: this job's index, and for the merge (K/K) the K-1 part files.
    std::optional<PartIndex> part;
    std::vector<std::string> merge;
    // The processes of an MPI job (process 0 runs this call; the others run_remote_range()).
    RangeProcesses* processes = nullptr;
};

// What a sort did. kSorted: the input was sorted out of core first and the sorted stream
// decimated; kCouldNot: kAuto found it out of streaming order but could not sort it (`why_not`);
// kNone: decimated as read.
struct SortOutcome {
    enum class Kind : uint8_t { kNone, kSorted, kCouldNot };
    Kind kind = Kind::kNone;
    bool requested = false;      // SortPolicy::kAlways (else kAuto decided)
    int axis = 0;                // the sort axis (kSorted)
    uint64_t detected_at = 0;    // kAuto: input triangles read when the first forced write came
    double attempt_seconds = 0;  // kAuto: the first attempt, abandoned there
    double sort_seconds = 0;     // reading (and spooling) the input and sorting it
    uint64_t temp_bytes = 0;     // peak temporary disk: the stdin spool and the sort's runs
    std::string why_not;         // kCouldNot
};

// The figures of a decimation, of which a caller makes its messages.
struct DecimateFacts {
    decimate::Stats stats;
    double ratio = 0;  // the ratio in use (decimator.ratio())
    bool target_given = false;
    size_t buffer = decimate::kDefaultBufferTriangles;
    bool default_buffer = true;     // the buffer is decimate::kDefaultBufferTriangles
    std::optional<int> given_axis;  // DecimateSettings::sorted_axis
    std::optional<int> file_axis;   // the axis the input says it is sorted along
    std::optional<int> used_axis;   // the axis the decimator swept along
    double weld_eps = 0;            // the weld's grid step
    std::string weld_text;          // the weld as the caller wrote it, for messages (the caller's)
    uint64_t skipped = 0;           // input triangles the read loop dropped
    std::string input_name;
    SortOutcome sort;
    // A target or ranges with an input that states no count: the first pass that counted it.
    std::optional<double> count_pass_seconds;
    bool count_pass_for_threads = false;  // made to cut the input into ranges (else for the target)
    // The ranges decimated at once (1: one stream decimator), the seam pass's buffer and the
    // triangles it force-wrote (kept apart from stats.forced_writes, the ranges').
    unsigned threads = 1;
    // MPI: the processes that decimated one range each (0: none; threads is then 1).
    unsigned processes = 0;
    // The merge of part jobs: the K ranges, K-1 of them from part files (0: none; threads is 1).
    unsigned parts = 0;
    size_t seam_buffer = 0;
    uint64_t seam_forced_writes = 0;
};

// A part file the merge read.
struct PartFileFacts {
    std::string path;
    unsigned k = 0;
    uint64_t triangles_in = 0;  // of its range
    uint64_t triangles = 0;     // in the file
};

struct DecimateResult {
    DecimateFacts facts;
    // What the job found besides the decimation's own figures: channels the output cannot hold
    // or rounds, the writer's notes, dropped input triangles, the reader's changes, ranges that
    // could not be used. (The caller adds its words for the decimation's figures.)
    Warnings warnings;
    std::string input_format, output_format;  // registry names
    bool input_gzip = false, output_gzip = false;
    uint64_t triangles_in = 0;  // read from the input
    uint64_t triangles_out = 0;
    std::vector<PartFileFacts> part_files;  // the merge's
};

// Decimates settings.input into settings.output (a part job: see decimate_part). Throws as the
// header says.
DecimateResult decimate_file(const DecimateSettings& settings, ProgressSink& progress);

// A part job k < K: range k-1 decimated into the part file settings.output.
struct PartResult {
    std::string input_name, input_format;
    bool input_gzip = false;
    uint64_t cut_triangles = 0;               // the count the ranges are cut from
    uint64_t range_first = 0, range_end = 0;  // the range's triangles, [first, end)
    uint64_t triangles_in = 0;                // the range's, decimated
    uint64_t triangles_out = 0;               // in the part file
    uint64_t part_file_bytes = 0;
    std::optional<double> count_pass_seconds;
};
PartResult decimate_part(const DecimateSettings& settings, ProgressSink& progress);

// An MPI process other than the first: receives process 0's plan, decimates its range and sends
// it (settings as process 0 has them).
void run_remote_range(const DecimateSettings& settings, RangeProcesses& processes);

}  // namespace meshstream::engine
