// Shared pieces of the `meshstream` subcommands: command-line option groups for reading and
// writing, byte-size parsing, the stderr progress bar, and the warning channel. Only tools/
// prints; the libraries report through return values and io::Error.
#pragma once

#include "engine/files.hpp"
#include "engine/progress.hpp"
#include "engine/units.hpp"
#include "engine/warnings.hpp"
#include "io/byte_stream.hpp"
#include "io/draco.hpp"
#include "io/format.hpp"
#include "io/gltf.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace meshstream::tools {

// The flag (or argument) that sets a library setting, as the libraries' messages name it:
// "--memory", "IN"; the command renders their errors and warnings with these.
std::string flag_name(io::Setting setting);
// A library error as the command says it: its settings named by their flags.
std::string describe_error(const std::exception& e);

// Counted warnings (engine::Warnings, with a stable code for --json: docs/cli.md lists them),
// printed once at the end of a command on stderr ("PROGRAM: warning: ...").
using engine::Warnings;
void print_warnings(const Warnings& warnings);

// A command line that cannot work, found after parsing (an option that needs a file given a
// stream, '-' without --to): exit code 2, like CLI11's own errors, before any work.
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Parses "256M", "64MiB", "1G", "1.5g", "4096" (bytes; K/M/G/T are binary multiples).
// Throws CLI::ValidationError on bad text.
uint64_t parse_bytes(const std::string& text);

// Options every command that reads a mesh accepts.
struct ReadFlags {
    std::string from;    // --from: force the input format
    std::string memory;  // --memory as given; empty: the default (kStreamingMemory, WholeMeshMemory)
    std::string tmpdir;
    bool strict = false;
    std::string drop;  // --drop (convert, sort): channel kinds not read
    io::ReadOptions options() const;
    // --memory's bytes, or kStreamingMemory when it is not given.
    uint64_t budget() const;
};
void add_read_flags(CLI::App* cmd, ReadFlags& flags);
// For commands that write a mesh: --memory's help adds the whole-mesh writers' default.
void describe_memory_for_writing(CLI::App* cmd);
// --drop's list, "normals,colors,uvs,extra,materials" (any of them, comma separated): the
// channel kinds to read, all but those named. Throws CLI::ValidationError naming an unknown
// name.
io::ChannelKinds kept_channel_kinds(const std::string& drop_list);
// --drop for convert and sort: the kinds named are not read, so not written, and their loss
// is not warned about.
void add_drop_flag(CLI::App* cmd, ReadFlags& flags);
// The cores of this machine (at least 1): --threads' default.
unsigned every_core();
// --threads N for convert, sort and decimate: `what` says what the threads (from 2) do, `details`
// (a second paragraph, for --help-all) how; the default (every core), "1: none" and the range
// 1..1024 are added.
void add_threads_option(CLI::App* cmd, unsigned& threads, const std::string& what, const std::string& details = {});
// For commands that measure the input as it is (info, compare): --strict's help says that it
// makes bad triangles errors, without the skipping that convert, sort and decimate do.
void strict_reports_bad_triangles(CLI::App* cmd);
// For decimate, which drops the triangles it cannot use: --strict's help says it makes them errors.
void strict_refuses_dropped_triangles(CLI::App* cmd);

// Options every command that writes a mesh accepts.
struct WriteFlags {
    std::string to;  // --to: force the output format
    int gzip_level = 6;
    std::string compress;   // --compress draco|meshopt|none (glTF); empty: not given (Draco)
    bool no_draco = false;  // --no-draco: the old spelling of --compress none
    bool normals = false;
    io::DracoSettings draco;  // --draco-qp, --draco-qn, --draco-qt, --draco-qc, --draco-cl
    // The glTF compression asked for: --compress, --no-draco, else Draco.
    io::GltfSettings::Compression compression() const;
    // The formats' own options given (Draco's and glTF's), for WriteOptions::format_options.
    io::FormatOptions format_options() const;
    // With --memory's budget, or, when it is not given, the default for `output`: the
    // whole-mesh one for a writer that holds the whole mesh (Format::kWholeMesh), else
    // kStreamingMemory.
    io::WriteOptions options(const ReadFlags& read, const io::Format& output) const;
};
// The files and options a convert or sort job takes from the flags (engine/convert.hpp); the
// caller adds its own (clean, threads, the axis).
template <class Settings>
Settings job_settings(const std::string& input, const std::string& output, const io::Format& out_format,
                      const ReadFlags& read, const WriteFlags& write) {
    Settings s;
    s.input = input;
    s.output = output;
    s.input_format = read.from;
    s.output_format = std::string(out_format.name);
    s.read = read.options();
    s.write = write.options(read, out_format);
    s.gzip_level = write.gzip_level;
    return s;
}
// `with_memory`: false when add_read_flags already added --memory/--tmpdir to `cmd`.
void add_write_flags(CLI::App* cmd, WriteFlags& flags);
// The format an output is written in: --to's, else its extension's, else, for stdout or a
// FIFO that is a pipe or socket, meshstream's triangle stream (io/triangle_stream.hpp). Throws
// UsageError (exit 2) when none applies ("-" on a terminal or a file without --to, a name
// whose extension is no writable format).
const io::Format& resolve_output_format(const std::string& output, const WriteFlags& flags);
// True when `output` ("-" = stdout) is a pipe or a socket.
bool names_a_pipe(const std::string& output);

using engine::input_files;
using engine::InputFiles;
using engine::refuse_output_over_inputs;
// This machine's memory (0 when the system does not say).
double physical_memory_bytes();

// --memory's default for streaming work: the tables of indexed formats, sort runs, spills.
inline constexpr uint64_t kStreamingMemory = io::kDefaultMemoryBudget;
// --memory's default for the writers that hold the whole mesh (Draco, glTF): half of the memory
// available (the MemAvailable line of `meminfo`, the text of /proc/meminfo), at least
// kStreamingMemory and at most kWholeMeshMemoryCeiling; kStreamingMemory when the text has no
// such line.
inline constexpr uint64_t kWholeMeshMemoryCeiling = uint64_t{64} << 30;
uint64_t whole_mesh_memory(std::string_view meminfo);
// The same for this machine, from /proc/meminfo, or from the file that the environment variable
// MESHSTREAM_MEMINFO names (for tests).
uint64_t whole_mesh_memory();
// Notes Draco/glTF options given for an output of another format, and --gzip-level for an
// output not named *.gz (they do nothing there).
void note_unused_write_flags(const WriteFlags& flags, const io::Format& output, const std::string& output_path,
                             Warnings& warnings);
using engine::dropped_channels_text;
using engine::note_input_changes;

// Global flags (set by main before a subcommand runs).
struct Global {
    bool quiet = false;
    // Nothing on stderr, warnings included: a caller that reports them itself (the Python
    // module returns them in its reports).
    bool silent = false;
    std::string program = "meshstream";  // the name diagnostics start with
};
Global& global();

// A one-line progress bar on stderr, drawn only when stderr is a terminal and --quiet is not
// given: phase label, count, rate, and percent + ETA when the total is known: the bytes read
// of the input file's size when the phase reads a file (any format, gzip too), else the count
// of its total. Redraws at most 5 times a second, so calling update() per chunk costs nothing.
class Progress final : public engine::ProgressSink {
public:
    Progress(std::string label, std::optional<uint64_t> total, std::string unit = "triangles");
    ~Progress() override;
    void update(uint64_t done) override;
    // The same while reading a file of `file_bytes` bytes as stored (nullopt: not a regular
    // file), of which `bytes_read` are read: percent and ETA come from the bytes.
    void update(uint64_t done, uint64_t bytes_read, std::optional<uint64_t> file_bytes) override;
    // update(done, ...) with the count read and the position of `source` in its file.
    void update(uint64_t done, const io::ByteSource& source) {
        update(done, source.stored_offset(), source.stored_size());
    }
    // Starts a new phase (keeps the bar); total may change.
    void phase(std::string label, std::optional<uint64_t> total) override;
    // Replaces the bar with one line of text until done() or the next update (a last step
    // that reports no counts, such as a writer assembling its file).
    void status(const std::string& text) override;
    void done();  // clears the line

private:
    void draw(bool force);
    std::string label_;
    std::optional<uint64_t> total_;
    std::string unit_;
    uint64_t done_ = 0;
    uint64_t bytes_read_ = 0;
    std::optional<uint64_t> file_bytes_;  // set by update(done, bytes, size) until phase()
    bool enabled_;
    bool drawn_ = false;
    bool fresh_phase_ = true;  // the first update of a phase draws at once
    std::chrono::steady_clock::time_point start_, last_;
};

using engine::human_bytes;
using engine::human_count;
using engine::is_regular_file;
using io::is_stream;  // "-", pipes, devices: read or written once only
// engine::input_bounds with the command's progress bar.
io::Bounds input_bounds(const std::string& path, std::string_view from, const io::ReadOptions& options);
using engine::longest_axis;
// Peak resident set size of this process in bytes (from /proc/self/status VmHWM).
uint64_t peak_rss_bytes();

}  // namespace meshstream::tools
