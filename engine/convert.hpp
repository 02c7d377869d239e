// One call per conversion and per sort, as `meshstream convert` and `meshstream sort` run them:
// any registered format to any other, every triangle and every channel the output can hold
// kept; or the same sorted out of core along one axis (sort/external_sort.hpp) with the axis
// recorded in the output, for the stream decimator.
//
// Memory: convert holds one chunk (seven with threads: the reader's three, the writer's three
// and its own) plus what the two formats need within their budgets (docs/formats.md). Sort
// splits SortSettings::read.memory_budget_bytes: a quarter for the reader's and writer's own
// tables, the rest for the runs, the merge buffers and the threads' chunks.
//
// Errors: io::Error for what cannot be read or written, io::OptionError for settings that cannot
// work with this input or output, Cancelled once the ProgressSink says so; an output that was not
// completed is removed.
#pragma once

#include "engine/progress.hpp"
#include "engine/warnings.hpp"
#include "io/format.hpp"
#include "sort/external_sort.hpp"

#include <cstdint>
#include <optional>
#include <string>

namespace meshstream::engine {

struct ConvertSettings {
    std::string input;          // a path, or "-" for stdin
    std::string output;         // a path, or "-" for stdout
    std::string input_format;   // registry name; empty: detected
    std::string output_format;  // registry name; empty: from the output's extension
    // Drop triangles with a NaN or infinite coordinate and degenerate ones, and count them (else
    // every triangle is kept).
    bool clean = false;
    // 2 or more: the input is read on a thread of its own and the output written on another
    // (io/pipeline.hpp); the same bytes out.
    unsigned threads = 1;
    io::ReadOptions read;    // memory budget, temporary directory, strict, channel kinds read
    io::WriteOptions write;  // the writer's memory budget and format options
    int gzip_level = 6;      // for an output named *.gz
};

// What a conversion or a sort did.
struct ConvertResult {
    Warnings warnings;  // channels the output cannot hold, writer notes, dropped triangles, ...
    std::string input_name, input_format, output_format;
    bool input_gzip = false, output_gzip = false;
    uint64_t triangles_in = 0, triangles_out = 0;
};

ConvertResult convert_file(const ConvertSettings& settings, ProgressSink& progress);

struct SortSettings : ConvertSettings {
    std::optional<int> axis;  // 0, 1, 2; none: the bounding box's longest (needs a file)
    // true: a writer that holds the whole mesh (glTF) gets a quarter of read.memory_budget_bytes
    // like any other; false: it gets write.memory_budget_bytes.
    bool writer_shares_budget = false;
    // The memory budget as the caller wrote it, for messages (empty: its size in binary units).
    std::string memory_text;
};

struct SortResult : ConvertResult {
    int axis = 0;
    sort::SortStats stats;
    double input_seconds = 0;  // reading the input and writing the runs
    double sort_seconds = 0;   // sorting the last run and the merge passes before the last
};

SortResult sort_file(const SortSettings& settings, ProgressSink& progress);

}  // namespace meshstream::engine
