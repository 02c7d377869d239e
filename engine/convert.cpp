// Conversions and sorts, one call each: see convert.hpp.
#include "engine/convert.hpp"

#include "engine/files.hpp"
#include "engine/units.hpp"
#include "io/error.hpp"
#include "io/pipeline.hpp"
#include "io/text_number.hpp"
#include "io/triangle_input.hpp"
#include "io/triangle_records.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>

namespace meshstream::engine {
namespace {

using io::mention;
using io::Setting;

std::string shown(const std::string& path, bool output) { return path != "-" ? path : output ? "<stdout>" : "<stdin>"; }

// The read loop: every triangle kept, or the bad ones dropped and counted (clean).
io::TriangleInput open_input(const ConvertSettings& s, const io::ReadOptions& options) {
    return io::TriangleInput(io::open_input(s.input, s.input_format, options),
                             s.clean ? io::BadTriangles::kDrop : io::BadTriangles::kKeep);
}

// What clean drops is said to be removed.
std::string removed() { return "removed (" + mention(Setting::kClean) + ")"; }

}  // namespace

ConvertResult convert_file(const ConvertSettings& s, ProgressSink& progress) {
    const io::Format& out_format = output_format(s.output, s.output_format);
    io::TriangleInput in = open_input(s, s.read);
    const io::MeshHeader& header = in.header();
    io::WriteOptions wo = s.write;
    // Every triangle is kept unless clean: the input's count is then the output's, promised to
    // the writer (binary STL and PLY put it first and need not patch or spool). With clean it is
    // an upper bound: a writer that puts a count first patches it (files) or spools the body
    // until it knows (stdout, gzip).
    if (!s.clean) wo.triangle_count = header.triangle_count;
    // PLY states its faces, each at least one triangle.
    wo.expected_triangle_count = header.triangle_count ? header.triangle_count : header.triangle_estimate;
    wo.sorted_axis = header.sorted_axis;
    // The kinds not asked for are not read: their loss is asked for, so it goes unsaid.
    const io::Channels wanted = s.read.channels.of(header.channels);
    wo.channels = io::writable_channels(out_format, wanted, wo);
    if (wo.channels.material) wo.materials = header.materials;
    const std::string dropped = io::describe_missing(wanted, wo.channels);
    refuse_output_over_inputs(s.output, out_format, wo, {input_files(s.input, header)});
    io::Output out = io::open_output(s.output, out_format.name, wo, s.gzip_level);

    // The chunk carries only what the output keeps: the reader fills no more.
    io::TriangleChunk chunk(io::TriangleChunk::kDefaultCapacity, wo.channels);
    progress.phase("converting", header.triangle_count);
    if (s.threads < 2) {
        while (in.next(chunk)) {
            out.write(chunk);
            progress.update(in.count().read, in.source().stored_offset(), in.source().stored_size());
            throw_if_cancelled(progress);
        }
    } else {
        // Reading (inflating, parsing) on one thread, writing (formatting, welding, encoding,
        // deflating) on another; this thread passes the chunks on and reports the progress.
        const std::optional<uint64_t> file_bytes = in.source().stored_size();
        io::WriteBehind writer(out, chunk.capacity(), chunk.channels());
        io::ReadAhead reader(in, chunk.capacity(), chunk.channels());
        while (true) {
            try {
                if (!reader.next(chunk)) break;
                throw_if_cancelled(progress);
            } catch (...) {
                // Without threads the writes before a read error come first: one of them may
                // fail instead, and that error is the run's.
                writer.close();
                throw;
            }
            writer.write(chunk);
            progress.update(reader.count().read, reader.stored_offset(), file_bytes);
        }
        writer.close();
    }
    // A reader may have added materials while reading (OBJ: names met after the first face).
    if (wo.channels.material) out.writer->update_materials(in.header().materials);
    // Whole-mesh formats encode, and spooled or compressed ones copy, only now: can be most of
    // the run.
    progress.status("converting: finishing " + std::string(out.format->name) + " output (" +
                    human_count(double(in.count().read)) + " triangles read)");
    out.finish();

    ConvertResult result;
    Warnings& warnings = result.warnings;
    for (const std::string& note : out.writer->raw_notes()) warnings.note("output_note", note);
    if (!dropped.empty()) warnings.note("channels_dropped", dropped_channels_text(dropped, *out.format, wo.channels));
    note_dropped_triangles(dropped_triangles(in), removed(), warnings);
    note_input_changes(in.header(), in.name(), warnings);
    result.input_name = in.name();
    result.input_format = std::string(in.format().name);
    result.input_gzip = in.source().gzip();
    result.output_format = std::string(out.format->name);
    result.output_gzip = s.output != "-" && io::wants_gzip(s.output);
    result.triangles_in = in.count().read;
    result.triangles_out = in.count().passed();
    return result;
}

SortResult sort_file(const SortSettings& s, ProgressSink& progress) {
    const auto t0 = std::chrono::steady_clock::now();
    const io::Format& out_format = output_format(s.output, s.output_format);
    // A writer that puts the triangles in an order of its own (Draco's connectivity coder)
    // would lose the sorted order.
    if (out_format.reorders_triangles != nullptr)
        if (const std::string why = out_format.reorders_triangles(s.write); !why.empty())
            throw io::OptionError(Setting::kTo, shown(s.output, true) + ": " + why +
                                                    ", so the sorted order would be lost: write STL, PLY or OBJ (or "
                                                    "glTF with " +
                                                    mention(Setting::kCompress) + " meshopt or none)");
    // Runs go beside a file output; a pipe or device (/dev/null, /dev/stdout) has no directory
    // of its own for them: /dev is memory.
    const bool output_stream = io::is_stream(s.output);
    if (!output_stream) {
        // Fail before a long sort, not after it.
        std::string dir = io::parent_dir(s.output);
        if (::access(dir.c_str(), W_OK) != 0)
            throw io::Error(s.output, "cannot write here: directory '" + dir + "' does not exist or is not writable");
    }
    // The budget is split: a quarter for the reader's and writer's own tables (indexed formats
    // weld or spill past their share; STL uses none of it), the rest for runs and merge buffers.
    const uint64_t budget = s.read.memory_budget_bytes;
    io::ReadOptions ro = s.read;
    ro.memory_budget_bytes = budget / 4;
    const std::string tmpdir = !s.read.tmpdir.empty() ? s.read.tmpdir
                               : !output_stream       ? io::parent_dir(s.output)
                                                      : std::string();
    ro.tmpdir = tmpdir;

    if (!s.axis && !is_regular_file(s.input))
        throw io::OptionError(Setting::kAxis, shown(s.input, false) + ": " + mention(Setting::kAxis) +
                                                  " auto reads the input twice (bounding box first), which needs a "
                                                  "regular file; give " +
                                                  mention(Setting::kAxis) + " x, y or z to sort a stream");
    if (s.axis && (*s.axis < 0 || *s.axis > 2))
        throw io::OptionError(Setting::kAxis,
                              "the sort axis must be 0, 1 or 2 (x, y or z), got " + std::to_string(*s.axis));
    io::TriangleInput in = open_input(s, ro);
    const io::MeshHeader header = in.header();
    SortResult result;
    result.input_name = in.name();  // the reader is released before the merge
    result.input_format = std::string(in.format().name);
    result.input_gzip = in.source().gzip();
    refuse_output_over_inputs(s.output, out_format, s.write, {input_files(s.input, header)});
    const int axis = s.axis ? *s.axis : longest_axis(input_bounds(s.input, s.input_format, ro, progress));
    sort::SorterOptions so;
    so.axis = axis;
    so.tmpdir = tmpdir;
    // Only the channels the output keeps are carried through the runs; the kinds not asked for
    // are not read: their loss is asked for, so it goes unsaid.
    const io::Channels wanted = ro.channels.of(header.channels);
    so.channels = io::writable_channels(out_format, wanted, s.write);
    const std::string dropped = io::describe_missing(wanted, so.channels);
    const size_t record_bytes = sort::ExternalSorter::record_bytes_for(so.channels);
    // The pipeline's chunks are part of the sorter's share: each at most 1/64 of the budget
    // (counted whether or not threads are used); a chunk holds a record and the positions.
    const size_t chunk_bytes = record_bytes + io::TriangleRecords::kPositionBytes;
    const size_t chunk_capacity =
        std::clamp<size_t>(budget / 64 / chunk_bytes, 256, io::TriangleChunk::kDefaultCapacity);
    const uint64_t pipe_bytes = io::kPipelineChunks * chunk_capacity * chunk_bytes;
    if (budget - budget / 4 <= pipe_bytes) {
        // The least budget b with b - b/4 > pipe_bytes (the pipe's size is fixed at such small
        // budgets: its chunks are at their minimum), in whole KiB.
        uint64_t least = pipe_bytes * 4 / 3;
        while (least - least / 4 <= pipe_bytes) ++least;
        const uint64_t least_kib = (least + 1023) / 1024;
        throw io::OptionError(Setting::kMemory, result.input_name + ": " + mention(Setting::kMemory) + " " +
                                                    (s.memory_text.empty() ? io::binary_size(budget) : s.memory_text) +
                                                    " is too small to sort: give at least " +
                                                    std::to_string(least_kib) + "K");
    }
    so.memory_budget_bytes = budget - budget / 4 - pipe_bytes;

    progress.phase("run generation", header.triangle_count);
    int shown_pass = 0;
    so.on_merge_progress = [&](int pass, int pass_count, uint64_t merged) {
        if (pass != shown_pass) {
            shown_pass = pass;
            progress.phase("merge pass " + std::to_string(pass) + "/" + std::to_string(pass_count), std::nullopt);
        }
        progress.update(merged);
    };
    sort::ExternalSorter sorter(so);
    {
        // With threads, the input is read, parsed and filtered on a thread of its own; this
        // thread adds the chunks to the runs (and sorts and spills each full run).
        io::TriangleChunk chunk(chunk_capacity, so.channels);
        const std::optional<uint64_t> file_bytes = in.source().stored_size();
        if (s.threads < 2) {
            while (in.next(chunk)) {
                sorter.add(chunk);
                progress.update(in.count().read, in.source().stored_offset(), file_bytes);
                throw_if_cancelled(progress);
            }
        } else {
            io::ReadAhead reader(in, chunk_capacity, so.channels);
            while (reader.next(chunk)) {
                sorter.add(chunk);
                progress.update(reader.count().read, reader.stored_offset(), file_bytes);
                throw_if_cancelled(progress);
            }
        }
    }
    // What the reader noted by the end of the input (a last line without a line end), before
    // it goes.
    const io::MeshHeader end_header = in.header();
    in.close();  // the reader's buffers and tables are not needed while merging
    result.input_seconds = seconds_since(t0);
    sorter.finish_input();
    result.sort_seconds = seconds_since(t0) - result.input_seconds;
    const uint64_t total = sorter.triangle_count();

    io::WriteOptions wo = s.write;
    // A writer that holds the whole mesh keeps its own budget unless it is to share this one.
    if (s.writer_shares_budget || !(out_format.traits & io::Format::kWholeMesh)) {
        wo.memory_budget_bytes = budget / 4;
        wo.memory_budget_divisor = 4;
    }
    wo.tmpdir = tmpdir;
    wo.triangle_count = total;
    wo.sorted_axis = axis;
    wo.channels = so.channels;
    if (wo.channels.material) wo.materials = end_header.materials;  // with materials added while reading
    io::Output out = io::open_output(s.output, out_format.name, wo, s.gzip_level);
    const int passes = sorter.stats().merge_passes;
    progress.phase(passes == 0 ? "writing" : "merge " + std::to_string(passes) + "/" + std::to_string(passes), total);
    {
        // With threads, the output is formatted and written on a thread of its own; this thread
        // merges (or gathers) the chunks.
        io::TriangleChunk chunk(chunk_capacity, so.channels);
        uint64_t done = 0;
        if (s.threads < 2) {
            while (sorter.next(chunk)) {
                out.write(chunk);
                progress.update(done += chunk.size());
                throw_if_cancelled(progress);
            }
        } else {
            io::WriteBehind writer(out, chunk_capacity, so.channels);
            while (sorter.next(chunk)) {
                const size_t n = chunk.size();
                writer.write(chunk);
                progress.update(done += n);
                if (progress.cancelled()) {
                    writer.close();
                    throw Cancelled();
                }
            }
            writer.close();
        }
    }
    out.finish();

    Warnings& warnings = result.warnings;
    for (const std::string& note : out.writer->raw_notes()) warnings.note("output_note", note);
    if (!dropped.empty()) warnings.note("channels_dropped", dropped_channels_text(dropped, *out.format, so.channels));
    // STL, PLY and OBJ have a place for the axis (a header or a comment); glTF has none.
    if (!out.format->sorted_axis_unrecorded.empty())
        warnings.note("sorted_axis_not_recorded", shown(s.output, true) + ": " +
                                                      std::string(out.format->sorted_axis_unrecorded) +
                                                      ": decimate it with " + mention(Setting::kSortedAxis) + " " +
                                                      "xyz"[axis] + ", or sort to STL, PLY or OBJ, which record it");
    note_dropped_triangles(dropped_triangles(in), removed(), warnings);
    note_input_changes(end_header, result.input_name, warnings);
    result.output_format = std::string(out.format->name);
    result.output_gzip = s.output != "-" && io::wants_gzip(s.output);
    result.triangles_in = in.count().read;
    result.triangles_out = total;
    result.axis = axis;
    result.stats = sorter.stats();
    return result;
}

}  // namespace meshstream::engine
