// Shared CLI helpers: option groups, sizes, progress bar, warnings.
#include "tools/common.hpp"

#include "tools/help.hpp"

#include "io/triangle_stream.hpp"

#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <thread>

namespace meshstream::tools {

uint64_t parse_bytes(const std::string& text) {
    double value = 0;
    const char* begin = text.data();
    const char* end = begin + text.size();
    auto [p, ec] = std::from_chars(begin, end, value);
    if (ec != std::errc() || !(value >= 0) || !std::isfinite(value))
        throw CLI::ValidationError("--memory", "expected a size like 64M or 1G, got '" + text + "'");
    std::string suffix(p, end);
    for (char& c : suffix) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    double mult = 1;
    if (suffix.empty() || suffix == "B")
        mult = 1;
    else if (suffix == "K" || suffix == "KB" || suffix == "KIB")
        mult = 1024.0;
    else if (suffix == "M" || suffix == "MB" || suffix == "MIB")
        mult = 1024.0 * 1024;
    else if (suffix == "G" || suffix == "GB" || suffix == "GIB")
        mult = 1024.0 * 1024 * 1024;
    else if (suffix == "T" || suffix == "TB" || suffix == "TIB")
        mult = 1024.0 * 1024 * 1024 * 1024;
    else
        throw CLI::ValidationError("--memory", "unknown size suffix in '" + text + "' (use K, M, G or T)");
    // Past 2^64 the conversion is undefined; the largest size is then refused as more than
    // this machine's memory, like any size too large.
    const double bytes = value * mult;
    return bytes >= 18446744073709551616.0 ? UINT64_MAX : static_cast<uint64_t>(bytes);
}

namespace {

using io::format_names;

// --from/--to take a registered format's name: a typo is a command-line error (exit 2).
CLI::Validator format_name(bool for_writing) {
    return CLI::Validator(
        [for_writing](std::string& name) -> std::string {
            const io::Format* f = io::find_format(name);
            if (f != nullptr && (for_writing ? f->open_writer != nullptr : f->open_reader != nullptr)) return {};
            return std::string("unknown ") + (for_writing ? "output" : "input") + " format '" + name +
                   "' (one of: " + format_names(for_writing) + ")";
        },
        "FORMAT");
}

}  // namespace

void note_unused_write_flags(const WriteFlags& flags, const io::Format& output, const std::string& output_path,
                             Warnings& warnings) {
    if (flags.gzip_level != WriteFlags{}.gzip_level && (output_path == "-" || !io::wants_gzip(output_path)))
        warnings.note("unused_option",
                      "--gzip-level applies to outputs named *.gz: ignored for " +
                          (output_path == "-" ? std::string("<stdout> (pipe it through gzip)") : output_path));
    const WriteFlags defaults;
    std::string draco_given;  // the Draco settings given, which only a Draco encoding uses
    auto add_to = [](std::string& list, bool set, const char* name) {
        if (set) list += (list.empty() ? "" : ", ") + std::string(name);
    };
    add_to(draco_given, flags.draco.position_bits != defaults.draco.position_bits, "--draco-qp");
    add_to(draco_given, flags.draco.normal_bits != defaults.draco.normal_bits, "--draco-qn");
    add_to(draco_given, flags.draco.texcoord_bits != defaults.draco.texcoord_bits, "--draco-qt");
    add_to(draco_given, flags.draco.color_bits != defaults.draco.color_bits, "--draco-qc");
    add_to(draco_given, flags.draco.level != defaults.draco.level, "--draco-cl");
    const bool compress_given = !flags.compress.empty() || flags.no_draco;
    auto verb = [](const std::string& list) { return list.find(',') == std::string::npos ? " applies" : " apply"; };
    // Which of these options the output's writer reads, as the format says.
    io::WriteOptions given_options;
    given_options.format_options = flags.format_options();
    auto takes = [&](const std::type_info& type) {
        return output.takes_options != nullptr && output.takes_options(type, given_options);
    };
    const bool takes_draco = takes(typeid(io::DracoSettings)), takes_gltf = takes(typeid(io::GltfSettings));
    if (takes_draco && !takes_gltf) {  // .drc
        if (compress_given && flags.compression() != io::GltfSettings::Compression::kDraco)
            warnings.note("unused_option", std::string(flags.no_draco ? "--no-draco" : "--compress") +
                                               " applies to glTF outputs; a .drc is always Draco");
        return;
    }
    if (takes_gltf) {
        if (!draco_given.empty() && !takes_draco)
            warnings.note("unused_option",
                          draco_given + verb(draco_given) + " to Draco compression: ignored with --compress " +
                              (flags.compression() == io::GltfSettings::Compression::kMeshopt ? "meshopt" : "none"));
        return;
    }
    std::string given;
    add_to(given, flags.normals, "--normals");
    add_to(given, compress_given, flags.no_draco ? "--no-draco" : "--compress");
    if (!draco_given.empty()) given += (given.empty() ? "" : ", ") + draco_given;
    if (!given.empty())
        warnings.note("unused_option",
                      given + verb(given) + " to Draco and glTF outputs only: ignored for " + std::string(output.name));
}

bool names_a_pipe(const std::string& output) {
    struct stat st;
    const int rc = output == "-" ? ::fstat(1, &st) : ::stat(output.c_str(), &st);
    return rc == 0 && (S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode));
}

const io::Format& resolve_output_format(const std::string& output, const WriteFlags& flags) {
    if (output.empty()) throw UsageError("the output name is empty");
    if (!flags.to.empty()) return *io::find_format(flags.to);  // checked by its validator
    if (const io::Format* f = io::format_for_extension(output, true)) return *f;
    // Between two commands nothing needs a count first: the triangle stream flows at once.
    if (names_a_pipe(output)) return io::kTriangleStreamFormat;
    if (output == "-")
        throw UsageError("<stdout>: writing to stdout needs --to unless it is a pipe (one of: " + format_names(true) +
                         ")");
    throw UsageError(output + ": cannot tell the output format from the name (use --to, one of: " + format_names(true) +
                     ")");
}

double physical_memory_bytes() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page_bytes = ::sysconf(_SC_PAGESIZE);
    return pages > 0 && page_bytes > 0 ? double(pages) * double(page_bytes) : 0;
}

uint64_t whole_mesh_memory(std::string_view meminfo) {
    size_t at = 0;
    while (at < meminfo.size()) {
        size_t end = meminfo.find('\n', at);
        if (end == std::string_view::npos) end = meminfo.size();
        std::string_view line = meminfo.substr(at, end - at);
        at = end + 1;
        if (!line.starts_with("MemAvailable:")) continue;
        line.remove_prefix(13);
        while (!line.empty() && line.front() == ' ') line.remove_prefix(1);
        uint64_t kib = 0;
        const auto [p, ec] = std::from_chars(line.data(), line.data() + line.size(), kib);
        if (ec != std::errc() || std::string_view(p, line.data() + line.size()) != " kB") break;
        const uint64_t half = kib > (UINT64_MAX >> 10) ? UINT64_MAX : (kib << 10) / 2;
        return std::clamp(half, kStreamingMemory, kWholeMeshMemoryCeiling);
    }
    return kStreamingMemory;
}

uint64_t whole_mesh_memory() {
    const char* path = std::getenv("MESHSTREAM_MEMINFO");
    std::ifstream in(path != nullptr && *path != '\0' ? path : "/proc/meminfo");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return whole_mesh_memory(text);
}

uint64_t ReadFlags::budget() const { return memory.empty() ? kStreamingMemory : parse_bytes(memory); }

io::ReadOptions ReadFlags::options() const {
    io::ReadOptions o;
    o.memory_budget_bytes = budget();
    // Tables and sort runs reserve their share of the budget up front (untouched pages cost
    // nothing), so a budget past the machine's memory failed as a bare "out of memory" even on
    // a tiny input.
    const double ram = physical_memory_bytes();
    if (ram > 0 && double(o.memory_budget_bytes) > ram)
        throw CLI::ValidationError("--memory", memory + " is more than this machine's memory (" + human_bytes(ram) +
                                                   "): give a smaller budget");
    o.tmpdir = tmpdir;
    o.strict = strict;
    o.channels = kept_channel_kinds(drop);
    return o;
}

namespace {

// --drop's list into `kinds`; the error text for an unknown name, else empty.
std::string parse_drop_list(const std::string& drop_list, io::ChannelKinds& kinds) {
    const std::pair<std::string_view, bool io::ChannelKinds::*> names[] = {{"normals", &io::ChannelKinds::normals},
                                                                           {"colors", &io::ChannelKinds::colors},
                                                                           {"uvs", &io::ChannelKinds::uvs},
                                                                           {"extra", &io::ChannelKinds::extras},
                                                                           {"materials", &io::ChannelKinds::materials}};
    size_t at = 0;
    while (at < drop_list.size()) {
        size_t end = drop_list.find(',', at);
        if (end == std::string::npos) end = drop_list.size();
        const std::string_view name = std::string_view(drop_list).substr(at, end - at);
        at = end + 1;
        if (name.empty()) continue;  // "normals," or "a,,b"
        bool known = false;
        for (const auto& [known_name, member] : names)
            if (name == known_name) kinds.*member = false, known = true;
        if (!known)
            return "unknown channel '" + std::string(name) + "' (one of: normals, colors, uvs, extra, materials)";
    }
    return {};
}

}  // namespace

io::ChannelKinds kept_channel_kinds(const std::string& drop_list) {
    io::ChannelKinds kinds;
    if (std::string error = parse_drop_list(drop_list, kinds); !error.empty())
        throw CLI::ValidationError("--drop", error);
    return kinds;
}

unsigned every_core() { return std::max(1u, std::thread::hardware_concurrency()); }

void add_threads_option(CLI::App* cmd, unsigned& threads, const std::string& what, const std::string& details) {
    cmd->add_option("--threads", threads,
                    what + " (default: every core, " + std::to_string(every_core()) + " here; 1: none)" +
                        (details.empty() ? "" : "\n" + details))
        ->type_name("N")
        ->check(CLI::Range(1u, 1024u));
}

void add_drop_flag(CLI::App* cmd, ReadFlags& flags) {
    cmd->add_option("--drop", flags.drop,
                    "channels not to read or write: normals,colors,uvs,extra,materials\n"
                    "Any of them, comma separated (extra: the named vertex and face properties); they are not read "
                    "and their loss is not warned about")
        ->type_name("LIST")
        ->check(CLI::Validator(
            [](const std::string& text) -> std::string {
                io::ChannelKinds kinds;
                return parse_drop_list(text, kinds);
            },
            ""));
}

void add_read_flags(CLI::App* cmd, ReadFlags& flags) {
    cmd->add_option("--memory", flags.memory,
                    "memory budget, e.g. 512M or 2G (default 256M)\n"
                    "Bounds the tables of indexed formats (PLY, OBJ), sort runs and spills; K, M, G, T are binary "
                    "multiples. A budget above this machine's memory is refused")
        ->type_name("SIZE");
    cmd->add_option("--tmpdir", flags.tmpdir, "where temporary files go (default: $TMPDIR or /tmp)")
        ->type_name("DIR")
        ->group(kMoreOptions);
    cmd->add_option("--from", flags.from,
                    "input format, instead of detection (e.g. stl-ascii)\nOne of: " + format_names(false))
        ->type_name("FMT")
        ->group(kMoreOptions)
        ->check(format_name(false));
    cmd->add_flag("--strict", flags.strict,
                  "make a counted recovery an error\n"
                  "Input a reader repairs (faces of fewer than 3 vertices), and what the output format cannot "
                  "hold (e.g. triangles Draco drops)")
        ->group(kMoreOptions);
}

void describe_memory_for_writing(CLI::App* cmd) {
    cmd->get_option("--memory")
        ->description(
            "memory budget, e.g. 512M or 2G (default 256M; Draco, glTF: half the available)\n"
            "Bounds the tables of indexed formats (PLY, OBJ), sort runs and spills (default 256M), and the mesh a "
            "Draco or glTF writer holds (default: half of the memory available, MemAvailable in /proc/meminfo, from "
            "256M to 64G); K, M, G, T are binary multiples. A budget above this machine's memory is refused");
}

void strict_refuses_dropped_triangles(CLI::App* cmd) {
    cmd->get_option("--strict")
        ->description(
            "make skipped triangles errors\n"
            "Triangles with a NaN/inf coordinate or two corners at the same position are skipped with a "
            "counted warning (decimate cannot use them); --strict makes them, and faces of fewer than 3 "
            "vertices and what the output format cannot hold, errors");
}

void strict_reports_bad_triangles(CLI::App* cmd) {
    cmd->get_option("--strict")
        ->description(
            "make bad triangles errors\n"
            "Makes the first triangle with a NaN/inf coordinate or two corners at the same position (or a "
            "face of fewer than 3 vertices) an error; without it they are counted as they are");
}

io::WriteOptions WriteFlags::options(const ReadFlags& read, const io::Format& output) const {
    io::WriteOptions o;
    o.memory_budget_bytes = !read.memory.empty()                       ? read.options().memory_budget_bytes
                            : (output.traits & io::Format::kWholeMesh) ? whole_mesh_memory()
                                                                       : kStreamingMemory;
    o.tmpdir = read.tmpdir;
    o.strict = read.strict;
    o.normals = normals;
    o.format_options = format_options();
    return o;
}

io::GltfSettings::Compression WriteFlags::compression() const {
    if (compress == "meshopt") return io::GltfSettings::Compression::kMeshopt;
    if (compress == "none" || (compress.empty() && no_draco)) return io::GltfSettings::Compression::kNone;
    return io::GltfSettings::Compression::kDraco;
}

io::FormatOptions WriteFlags::format_options() const {
    io::FormatOptions o;
    o.set(draco);
    o.set(io::GltfSettings{compression()});
    return o;
}

void add_write_flags(CLI::App* cmd, WriteFlags& flags) {
    cmd->add_option("--to", flags.to,
                    "output format, instead of the extension's (e.g. ply, glb)\nOne of: " + format_names(true) +
                        ". Without it, '-' on a pipe gets meshstream's triangle stream, which the next command reads "
                        "as it comes; --to stl or ply to a pipe spools the body to --tmpdir first (their count goes "
                        "before it)")
        ->type_name("FMT")
        ->check(format_name(true));
    cmd->add_option("--gzip-level", flags.gzip_level, "zlib level 0-9 for outputs named *.gz (default 6)")
        ->type_name("N")
        ->group(kMoreOptions)
        ->check(CLI::Range(0, 9));
    // Draco (.drc) and glTF (.glb/.gltf) hold the whole mesh in memory (docs/formats.md).
    auto* compress = cmd->add_option("--compress", flags.compress,
                                     "glTF compression: draco (default), meshopt or none\n"
                                     "draco: KHR_draco_mesh_compression with the --draco-* settings; meshopt: "
                                     "EXT_meshopt_compression with 14-bit quantized positions, like gltfpack -cc "
                                     "(viewers need a meshopt decoder, e.g. three.js's MeshoptDecoder); none: plain "
                                     "float accessors")
                         ->type_name("KIND")
                         ->group(kWebOptions)
                         ->check(CLI::IsMember({"draco", "meshopt", "none"}));
    cmd->add_flag("--no-draco", flags.no_draco, "the same as --compress none")->group(kWebOptions)->excludes(compress);
    cmd->add_flag("--normals", flags.normals, "add smooth vertex normals to a mesh without normals of its own")
        ->group(kWebOptions);
    cmd->add_option("--draco-qp", flags.draco.position_bits, "Draco position quantization bits, 1-30 (default 14)")
        ->type_name("N")
        ->group(kWebOptions)
        ->check(CLI::Range(1, 30));
    // Draco's octahedral normal coder needs 2 bits or more (1 fails inside its encoder).
    cmd->add_option("--draco-qn", flags.draco.normal_bits, "Draco normal quantization bits, 2-30 (default 10)")
        ->type_name("N")
        ->group(kWebOptions)
        ->check(CLI::Range(2, 30));
    cmd->add_option("--draco-qt", flags.draco.texcoord_bits,
                    "Draco texture coordinate quantization bits, 1-30 (default 12)")
        ->type_name("N")
        ->group(kWebOptions)
        ->check(CLI::Range(1, 30));
    cmd->add_option("--draco-qc", flags.draco.color_bits,
                    "Draco bits of float colours and named scalars, 1-30 (default 10)\n"
                    "Integer colours and scalars are kept exactly")
        ->type_name("N")
        ->group(kWebOptions)
        ->check(CLI::Range(1, 30));
    cmd->add_option("--draco-cl", flags.draco.level,
                    "Draco compression level 0-10 (default 7)\n"
                    "Higher is slower, and usually smaller")
        ->type_name("N")
        ->group(kWebOptions)
        ->check(CLI::Range(0, 10));
}

Global& global() {
    static Global g;
    return g;
}

namespace {
// A bar redraws its line with \r and erases with ESC [K: only on a terminal that has both.
bool bar_terminal() {
    const char* term = std::getenv("TERM");
    return ::isatty(2) && term != nullptr && *term != '\0' && std::string_view(term) != "dumb";
}

// Writes `text` over the bar's line, cut to the terminal's width: a line that wrapped would
// leave its first rows behind when the next frame or done() returns to its start.
void draw_line(std::string_view text) {
    struct winsize ws;
    const size_t width = ::ioctl(2, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 1 ? ws.ws_col - 1 : 79;
    if (text.size() > width) text = text.substr(0, width);
    std::fprintf(stderr, "\r%.*s\x1b[K", int(text.size()), text.data());
}
}  // namespace

Progress::Progress(std::string label, std::optional<uint64_t> total, std::string unit)
    : label_(std::move(label)),
      total_(total),
      unit_(std::move(unit)),
      enabled_(!global().quiet && bar_terminal()),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

Progress::~Progress() { done(); }

void Progress::phase(std::string label, std::optional<uint64_t> total) {
    label_ = std::move(label);
    total_ = total;
    done_ = 0;
    bytes_read_ = 0;
    file_bytes_.reset();
    start_ = std::chrono::steady_clock::now();
    draw(true);
    fresh_phase_ = true;
}

void Progress::status(const std::string& text) {
    if (!enabled_) return;
    draw_line(text);
    drawn_ = true;
}

// The first update of a phase draws at once (a phase shows its counts from its first chunk),
// the others at most 5 times a second.
void Progress::update(uint64_t done) {
    done_ = done;
    if (enabled_) draw(fresh_phase_ || !drawn_);
    fresh_phase_ = false;
}

void Progress::update(uint64_t done, uint64_t bytes_read, std::optional<uint64_t> file_bytes) {
    done_ = done;
    bytes_read_ = bytes_read;
    file_bytes_ = file_bytes;
    if (enabled_) draw(fresh_phase_ || !drawn_);
    fresh_phase_ = false;
}

void Progress::draw(bool force) {
    if (!enabled_) return;
    auto now = std::chrono::steady_clock::now();
    if (!force && now - last_ < std::chrono::milliseconds(200)) return;
    last_ = now;
    double secs = std::chrono::duration<double>(now - start_).count();
    double rate = secs > 0 ? done_ / secs : 0;
    char line[256];
    // The share done: of the file's bytes when reading one (every format, gzip too), else of
    // the count's total.
    std::optional<double> share;
    if (file_bytes_ && *file_bytes_ > 0)
        share = double(bytes_read_) / double(*file_bytes_);
    else if (total_ && *total_ > 0)
        share = double(done_) / double(*total_);
    if (share) {
        const double frac = std::min(1.0, *share);
        int filled = static_cast<int>(frac * 24);
        std::string bar(filled, '#');
        bar.resize(24, '.');
        const double eta = frac > 0 ? secs * (1 - frac) / frac : 0;
        std::snprintf(line, sizeof line, "%s [%s] %5.1f%% %s %s, %s/s, ETA %.0fs", label_.c_str(), bar.c_str(),
                      100 * frac, human_count(done_).c_str(), unit_.c_str(), human_count(rate).c_str(), eta);
    } else {
        std::snprintf(line, sizeof line, "%s %s %s, %s/s, %.0fs", label_.c_str(), human_count(done_).c_str(),
                      unit_.c_str(), human_count(rate).c_str(), secs);
    }
    draw_line(line);
    drawn_ = true;
}

void Progress::done() {
    if (enabled_ && drawn_) std::fputs("\r\x1b[K", stderr);
    drawn_ = false;
}

std::string flag_name(io::Setting setting) {
    static constexpr const char* kFlags[io::kSettingCount] = {
        "IN",
        "OUT",
        "--from",
        "--to",
        "--memory",
        "--tmpdir",
        "--strict",
        "--drop",
        "--clean",
        "--compress",
        "--draco-qp",
        "--draco-qn",
        "--draco-qt",
        "--draco-qc",
        "--draco-cl",
        "--gzip-level",
        "--ratio",
        "--target",
        "--buffer",
        "--weld",
        "--weights",
        "--sorted-axis",
        "--seed",
        "--threads",
        "--sort",
        "--axis",
        "--part",
        "--merge",
        "--attributes",
        "the output chunk size",  // no flag: the commands write chunks of the default size
        "--tile-triangles",
        "--origin",
        "--overwrite",
    };
    const int i = int(setting);
    return i >= 0 && i < io::kSettingCount ? kFlags[i] : std::string(io::setting_words(setting));
}

std::string describe_error(const std::exception& e) {
    if (const auto* error = dynamic_cast<const meshstream::Error*>(&e)) return error->describe(flag_name);
    return e.what();
}

void print_warnings(const Warnings& warnings) {
    if (global().silent) return;
    for (const std::string& line : warnings.lines(flag_name))
        std::fprintf(stderr, "%s: warning: %s\n", global().program.c_str(), line.c_str());
}

io::Bounds input_bounds(const std::string& path, std::string_view from, const io::ReadOptions& options) {
    Progress progress("bounding box", std::nullopt);
    return engine::input_bounds(path, from, options, progress);
}

uint64_t peak_rss_bytes() {
    std::ifstream status("/proc/self/status");
    std::string key;
    while (status >> key) {
        if (key == "VmHWM:") {
            uint64_t kb = 0;
            status >> kb;
            return kb * 1024;
        }
        status.ignore(1 << 16, '\n');
    }
    return 0;
}

}  // namespace meshstream::tools
