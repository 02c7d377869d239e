// `meshstream sort IN OUT`: out-of-core pre-sorting of a triangle stream along one axis, for
// the stream decimator (sort/external_sort.hpp does the sorting; docs/sorting.md explains the
// method and the memory bound). This file chooses the axis, splits --memory between the
// reader/writer and the sorter, drives the progress bar and records the axis in the output.
#include "io/error.hpp"
#include "sort/external_sort.hpp"
#include "tools/commands.hpp"
#include "tools/common.hpp"
#include "tools/input_filter.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

namespace meshstream::tools {
namespace {

struct SortOptions {
    std::string input, output;
    std::string axis = "auto";
    bool stats = false;
    ReadFlags read;
    WriteFlags write;
};

const char* const kAxisNames[] = {"x", "y", "z"};

// The longest axis of the input's bounding box, from the header when it states the bounds,
// else from a first reading pass. Precondition: the input can be opened twice.
int longest_axis(const SortOptions& opt, const io::ReadOptions& ro) {
    io::Input in = io::open_input(opt.input, opt.read.from, ro);
    std::array<float, 3> lo, hi;
    if (in.reader->header().bounds) {
        lo = in.reader->header().bounds->min;
        hi = in.reader->header().bounds->max;
    } else {
        lo.fill(std::numeric_limits<float>::infinity());
        hi.fill(-std::numeric_limits<float>::infinity());
        io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, in.reader->header().channels);
        Progress progress("bounding box", in.reader->triangle_count());
        uint64_t done = 0;
        while (in.reader->next(chunk)) {
            auto xyz = chunk.xyz();
            for (size_t i = 0; i < xyz.size(); i += 3)
                for (int a = 0; a < 3; ++a)
                    if (std::isfinite(xyz[i + a])) {  // a NaN or inf corner would decide nothing
                        lo[a] = std::min(lo[a], xyz[i + a]);
                        hi[a] = std::max(hi[a], xyz[i + a]);
                    }
            progress.update(done += chunk.size());
        }
    }
    int best = 2;  // empty or flat input: z, the usual scan axis
    double best_extent = 0;
    for (int a = 0; a < 3; ++a) {
        double extent = double(hi[a]) - double(lo[a]);
        if (extent > best_extent) {
            best_extent = extent;
            best = a;
        }
    }
    return best;
}

bool is_regular_file(const std::string& path) {
    struct stat st;
    return path != "-" && ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

void run_sort(const SortOptions& opt) {
    const auto t0 = std::chrono::steady_clock::now();
    if (opt.output != "-") {
        // Fail before a long sort, not after it.
        std::string dir = io::parent_dir(opt.output);
        if (::access(dir.c_str(), W_OK) != 0)
            throw io::Error(opt.output, "cannot write here: directory '" + dir + "' does not exist or is not writable");
    }
    // --memory is split: a quarter for the reader's and writer's own tables (indexed formats
    // weld or spill past their share; STL uses none of it), the rest for runs and merge buffers.
    const uint64_t budget = opt.read.options().memory_budget_bytes;
    io::ReadOptions ro = opt.read.options();
    ro.memory_budget_bytes = budget / 4;
    const std::string tmpdir = !opt.read.tmpdir.empty() ? opt.read.tmpdir
                               : opt.output != "-"     ? io::parent_dir(opt.output)
                                                       : std::string();
    ro.tmpdir = tmpdir;

    int axis;
    if (opt.axis == "auto") {
        if (!is_regular_file(opt.input))
            throw io::Error(opt.input == "-" ? "<stdin>" : opt.input,
                            "--axis auto reads the input twice (bounding box first), which needs a regular file; "
                            "give --axis x, y or z to sort a stream");
        axis = longest_axis(opt, ro);
    } else {
        axis = static_cast<int>(std::find(std::begin(kAxisNames), std::end(kAxisNames), opt.axis) - std::begin(kAxisNames));
    }

    io::Input in = io::open_input(opt.input, opt.read.from, ro);
    const io::MeshHeader header = in.reader->header();
    sort::SorterOptions so;
    so.axis = axis;
    so.tmpdir = tmpdir;
    so.channels = header.channels;
    const size_t record_bytes = sort::ExternalSorter::record_bytes_for(so.channels);
    // The chunk is part of the sorter's share: at most 1/16 of the budget.
    const size_t chunk_capacity =
        std::clamp<size_t>(budget / 16 / (record_bytes + 36), 256, io::TriangleChunk::kDefaultCapacity);
    so.memory_budget_bytes = budget - budget / 4 - chunk_capacity * (record_bytes + 36);

    Progress progress("run generation", header.triangle_count);
    int shown_pass = 0;
    so.on_merge_progress = [&](int pass, int pass_count, uint64_t merged) {
        if (pass != shown_pass) {
            shown_pass = pass;
            progress.phase("merge pass " + std::to_string(pass) + "/" + std::to_string(pass_count),
                           std::nullopt);
        }
        progress.update(merged);
    };
    sort::ExternalSorter sorter(so);
    io::TriangleChunk chunk(chunk_capacity, header.channels);
    uint64_t done = 0;
    TriangleFilter filter(in.source->name(), opt.read.strict);
    while (in.reader->next(chunk)) {
        progress.update(done += chunk.size());
        filter.apply(chunk);
        sorter.add(chunk);
    }
    if (header.triangle_count && done != *header.triangle_count)
        throw io::Error(in.source->name(), "header promises " + std::to_string(*header.triangle_count) +
                                               " triangles, read " + std::to_string(done));
    in = {};  // the reader's buffers and tables are not needed while merging
    sorter.finish_input();
    const uint64_t total = sorter.triangle_count();

    io::WriteOptions wo = opt.write.options(opt.read);
    wo.memory_budget_bytes = budget / 4;
    wo.tmpdir = tmpdir;
    wo.triangle_count = total;
    wo.sorted_axis = axis;
    io::Output out = io::open_output(opt.output, opt.write.to, wo, opt.write.gzip_level);
    const int passes = sorter.stats().merge_passes;
    progress.phase(passes == 0 ? "writing" : "merge " + std::to_string(passes) + "/" + std::to_string(passes), total);
    done = 0;
    while (sorter.next(chunk)) {
        out.write(chunk);
        progress.update(done += chunk.size());
    }
    out.finish();
    progress.done();
    Warnings warnings;
    filter.report(warnings);
    warnings.print();

    if (opt.stats) {
        const sort::SortStats& s = sorter.stats();
        double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::fprintf(stderr,
                     "sorted %llu triangles along %s in %.2f s (%s triangles/s): %llu runs of up to %llu, "
                     "%d merge passes, %s temporary written, peak temporary disk %s, peak RSS %s\n",
                     (unsigned long long)s.triangles, kAxisNames[axis], seconds,
                     human_count(seconds > 0 ? double(s.triangles) / seconds : 0).c_str(), (unsigned long long)s.runs,
                     (unsigned long long)s.run_capacity, s.merge_passes, human_bytes(double(s.temp_bytes_written)).c_str(),
                     human_bytes(double(s.peak_temp_bytes)).c_str(), human_bytes(double(peak_rss_bytes())).c_str());
    }
}

}  // namespace

void add_sort(CLI::App& app) {
    auto opt = std::make_shared<SortOptions>();
    CLI::App* cmd = app.add_subcommand(
        "sort", "Sort triangles by their minimum coordinate along an axis (out of core, stable), so that\n"
                "decimate can stream them; the output records the axis (see docs/sorting.md)");
    cmd->add_option("input", opt->input, "Input mesh ('-' = stdin, needs --axis x|y|z)")->required();
    cmd->add_option("output", opt->output, "Output mesh ('-' = stdout, needs --to)")->required();
    cmd->add_option("--axis", opt->axis, "x, y, z, or auto: the longest bounding-box axis (default; needs a file)")
        ->check(CLI::IsMember({"x", "y", "z", "auto"}));
    cmd->add_flag("--stats", opt->stats, "Print runs, merge passes, temporary disk, time and peak RSS on stderr");
    add_read_flags(cmd, opt->read);
    add_write_flags(cmd, opt->write);
    cmd->callback([opt] { run_sort(*opt); });
}

}  // namespace meshstream::tools
