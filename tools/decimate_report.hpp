// What `meshstream decimate` tells its user, built from the run's statistics apart from the
// run itself: the summary lines, the notice of a sort it did first (--sort), and the counted
// warnings (forced writes and their remedy, a missed target and why, an unwelded surface...).
// Plain functions of plain facts, so each message can be tested without a mesh.
#pragma once

#include "decimate/stream_decimator.hpp"
#include "tools/common.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>

namespace meshstream::tools {

// What --sort did. kSorted: the input was sorted out of core first and the sorted stream
// decimated; kCouldNot: --sort auto found it out of streaming order but could not sort it
// (`why_not`); kNone: decimated as read.
struct SortOutcome {
    enum class Kind : uint8_t { kNone, kSorted, kCouldNot };
    Kind kind = Kind::kNone;
    bool requested = false;      // --sort always (else auto decided)
    int axis = 0;                // the sort axis (kSorted)
    uint64_t detected_at = 0;    // auto: input triangles read when the first forced write came
    double attempt_seconds = 0;  // auto: the first attempt, abandoned there
    double sort_seconds = 0;     // reading (and spooling) the input and sorting it
    uint64_t temp_bytes = 0;     // peak temporary disk: the stdin spool and the sort's runs
    std::string why_not;         // kCouldNot
};

// The facts the messages are made of.
struct DecimateFacts {
    decimate::Stats stats;
    double ratio = 0;               // the ratio in use (decimator.ratio())
    bool target_given = false;      // --target
    size_t buffer = 400000;         // --buffer
    bool default_buffer = true;     // --buffer not given
    std::optional<int> given_axis;  // --sorted-axis
    std::optional<int> file_axis;   // the axis the input says it is sorted along
    std::optional<int> used_axis;   // the axis the decimator swept along
    double weld_eps = 0;            // --weld, as a size
    std::string weld_text;          // --weld as given
    uint64_t skipped = 0;           // input triangles the read loop dropped
    std::string input_name;
    SortOutcome sort;
    // --target or --threads with an input that states no count: the first pass that counted it.
    std::optional<double> count_pass_seconds;
    bool count_pass_for_threads = false;  // made to cut the input into ranges (else for --target)
    // --threads: the ranges decimated at once (1: one stream decimator), the seam pass's buffer
    // and the triangles it force-wrote (kept apart from stats.forced_writes, the ranges').
    unsigned threads = 1;
    // meshstream-mpi: the processes (MPI ranks) that decimated one range each (0: none; threads
    // is then 1).
    unsigned processes = 0;
    // --part K/K (the merge job): the K ranges, K-1 of them decimated by other jobs into part
    // files (0: none; threads is then 1).
    unsigned parts = 0;
    size_t seam_buffer = 0;
    uint64_t seam_forced_writes = 0;
};

// The warnings about the decimation itself (not the read loop's or the writer's, which the
// command adds), in the order they are printed.
void note_decimate_warnings(const DecimateFacts& facts, Warnings& warnings);

// "sorted along x first (...): 1.23 s, 36.0 MB of temporary disk"; empty unless kSorted.
std::string sort_notice(const SortOutcome& sort);

// The decimation's own figures for --json (run_report.hpp): target, ratio, buffer and its peak
// fill, collapses, forced writes, the sweep axis, the weld, a sort done first and the threads.
nlohmann::ordered_json decimate_details_json(const DecimateFacts& facts);

// "counted N input triangles in a first pass for --target (...): 0.12 s" (or "to cut it into
// ranges for --threads").
std::string count_pass_notice(uint64_t triangles, double seconds, bool for_threads = false);

// The summary lines on stderr after a run (triangles, time, buffer, weld, sweep, sort).
void print_decimate_summary(const DecimateFacts& facts, const std::string& output, double seconds);

}  // namespace meshstream::tools
