// What `meshstream decimate` tells its user, built from the run's statistics apart from the
// run itself: the summary lines, the notice of a sort it did first (--sort), and the counted
// warnings (forced writes and their remedy, a missed target and why, an unwelded surface...).
// Plain functions of plain facts, so each message can be tested without a mesh.
#pragma once

#include "engine/decimate.hpp"
#include "tools/common.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>

namespace meshstream::tools {

// The run's figures (engine/decimate.hpp): what --sort did, and the decimation's facts.
using engine::DecimateFacts;
using engine::SortOutcome;

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
