// Readers, writers and the format descriptor. A format describes itself next to its code
// (PDAL's StaticPluginInfo, OpenMesh's get_extensions/get_magic); io/registry.cpp lists them.
// Adding a format = io/<fmt>.{hpp,cpp} + one line in registry.cpp + its CMake source line.
#pragma once

#include "io/byte_stream.hpp"
#include "io/chunk.hpp"
#include "io/error.hpp"

#include <any>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <typeinfo>
#include <utility>
#include <vector>

namespace meshstream::io {

struct Bounds {
    std::array<float, 3> min{}, max{};
};

// An image a material refers to. `uri` is the name the source gave it (relative to the source
// file's directory, or a data: URI's media type only); `bytes` its content when the reader
// could load it (GLB, data URIs, a file beside an OBJ's MTL or a .gltf), else empty.
struct Texture {
    std::string uri;
    std::string mime_type;  // "image/png", "image/jpeg", or empty when not known
    std::vector<std::byte> bytes;
    bool operator==(const Texture&) const = default;
};

// One entry of a stream's material table; triangles refer to it by index (the chunk's material
// channel). Readers keep what the formats share: a name, a base colour and its texture.
struct Material {
    std::string name;
    std::array<float, 4> base_color{1.0f, 1.0f, 1.0f, 1.0f};  // linear RGBA (OBJ's Kd and d)
    std::optional<Texture> texture;                           // base colour texture (map_Kd)
    bool operator==(const Material&) const = default;
};

// Something a reader repaired or skipped because the file's intent was clear (a header line
// that is no PLY keyword, an STL facet of four corners, a face of two), or could not keep (a
// PLY list property): one entry per kind, counted, with where the first one was. The
// commands print each once, with its count, as a warning; under ReadOptions::strict the
// readers throw io::Error instead for what is bad input.
struct ReaderWarning {
    // What happened, e.g. "faces with fewer than 3 corners skipped"; settings in it are mentions
    // (io::mention), which io::render() words.
    std::string text;
    uint64_t count = 0;                         // how often
    uint64_t first_line = 0;                    // of the first one: 1-based line, 0 = not known
    uint64_t first_byte_offset = ~uint64_t{0};  // and byte offset, ~0 = not known
    bool operator==(const ReaderWarning&) const = default;
};
// " (first at line L, byte B)" (" (at ...)" for one), or "" when the position is not known.
std::string warning_position(const ReaderWarning& warning);
// "<file>: <text> (first at line L, byte B)", for a message (the count is the caller's); the
// mentions are kept, for io::render().
std::string describe_warning(const std::string& file, const ReaderWarning& warning);

// What a reader knows from the file's header, before or while streaming. Every field is
// optional: formats fill what they know.
struct MeshHeader {
    std::optional<uint64_t> triangle_count;  // total triangles (an n-gon counts n - 2)
    // Where the count is not stated up front: about this many (PLY: its faces, each counted as
    // one triangle, as the header cannot tell polygons). A hint, e.g. for which mesh to hold.
    std::optional<uint64_t> triangle_estimate;
    std::optional<uint64_t> vertex_count;  // indexed formats
    std::optional<int> sorted_axis;        // 0,1,2 when the file says it is sorted (meshstream sort)
    Channels channels;                     // channels the reader will fill
    // The table the material channel indexes. A reader may append to it while reading (OBJ: a
    // `usemtl` name that no MTL file defines, met after the first face); entries already in it
    // never change, so the table as it stands after the last next() holds every index read.
    std::vector<Material> materials;
    std::string variant;                                     // e.g. "binary", "ascii", "binary_big_endian"
    // Extra facts for `info` (key, text); a text may mention settings (io::mention), which
    // io::render() words.
    std::vector<std::pair<std::string, std::string>> notes;
    // Files besides the input that the reader read (a .gltf's buffer files, an OBJ's .mtl and
    // textures), so the commands can refuse an output that would overwrite one of them.
    std::vector<std::string> side_files;
    // Set by readers of double coordinates (PLY) once they are read: the largest change that
    // rounding them to float made (0: none). The commands warn when it is above 0.
    std::optional<double> coordinate_rounding;
    // What the reader repaired, skipped or could not keep so far (complete once next() has
    // returned false); see ReaderWarning.
    std::vector<ReaderWarning> warnings;
};
// The note such a reader adds for `info`, saying the same in words.
inline constexpr const char* kPrecisionNote = "coordinates";
// The note a text reader adds when the file's last line has no line end, as when a download or
// a pipe was cut inside the last number ("f 10 11 1" from "f 10 11 12"), which no count or
// syntax can show. The commands repeat it as a warning.
inline constexpr const char* kLastLineNote = "last line";
inline constexpr const char* kLastLineText = "has no line end: the file may be cut short inside it";

// A way to an IndexedSource's vertices for a thread of its own (IndexedSource::split_lookup).
class VertexLookup {
public:
    virtual ~VertexLookup() = default;
    // As IndexedSource::vertex.
    virtual void vertex(uint64_t i, float* xyz, std::byte* record) = 0;
    // A hint that vertex(i) comes soon (i < vertex_count()): its bytes are asked of memory ahead.
    virtual void prefetch(uint64_t i) = 0;
};

// What a reader of an indexed format gives a whole-mesh read (io::read_indexed) instead of its
// triangle soup, when every corner carries nothing but its vertex's values (PLY): the file's
// own vertices, in file order, and its faces as indices into them, so that nothing is welded
// again. See Reader::indexed().
class IndexedSource {
public:
    virtual ~IndexedSource() = default;
    // The vertices the faces index (all of the file's, referenced or not); fewer than 2^32.
    virtual uint64_t vertex_count() const = 0;
    // The bytes of the reader's vertex table: with a memory budget of this and 64 KiB more, a
    // reader of the same file holds it whole, and reads each vertex's page once.
    virtual uint64_t vertex_table_bytes() const = 0;
    // Vertex i (< vertex_count()): xyz[3] and, when `record` is non-null, its values as
    // CornerLayout(channels) packs them, `channels` being what the reader stores (ReadOptions::
    // channels of the header's). Cheapest in order.
    virtual void vertex(uint64_t i, float* xyz, std::byte* record) = 0;
    // The positions of vertices [first, first + count) (<= vertex_count()) into xyz, 3 floats
    // each, read in bulk: the cheapest way through all of them in order.
    virtual void positions(uint64_t first, uint64_t count, float* xyz) = 0;
    // A hint that vertex(i) comes soon (i < vertex_count()).
    virtual void prefetch(uint64_t i) = 0;
    // A second way to the vertices for another thread, safe beside this source's own reading
    // (faces and vertices) on one other thread; a vertex table read through a cache gives it half
    // of its budget. It must not outlive this source.
    virtual std::unique_ptr<VertexLookup> split_lookup() = 0;
    // Appends the triangles of the next faces (about `max` of them, a polygon triangulated as
    // next() would), 3 vertex indices each, counter-clockwise; returns false, appending
    // nothing, once the faces are done and the rest of the file checked. Throws io::Error for
    // what next() would.
    virtual bool next_triangles(std::vector<uint32_t>& indices, size_t max) = 0;
};

class Reader {
public:
    virtual ~Reader() = default;
    // The file's vertices and faces for a whole-mesh read, before any next(), from readers
    // that can give them (IndexedSource); the others, and a reader that was read from, return
    // null. A reader that returns one is then read through it only (never next()).
    virtual IndexedSource* indexed() { return nullptr; }
    // Fills `chunk` (cleared first) with up to chunk.capacity() triangles; returns false once
    // the input is exhausted (chunk then empty). Fills only the channels the chunk was made
    // with (header().channels are those the reader can fill). Throws io::Error on bad input
    // and never emits a partial triangle.
    virtual bool next(TriangleChunk& chunk) = 0;
    // Makes the reader deliver the triangles [first, end) of the input only, reading none
    // before `first`, and returns true, when its records have a fixed size in a source that
    // can seek (a binary STL, or meshstream's triangle stream whose header states its count, in
    // a plain regular file) and its header at the end says of those
    // triangles what it would of all of them (nothing counted while reading). Otherwise
    // returns false and changes nothing. Call it before the first next(), with first <= end <=
    // the header's triangle count.
    virtual bool select_triangles(uint64_t first, uint64_t end) {
        (void)first, (void)end;
        return false;
    }
    // Facts from the header; triangle_count is set when the format states it up front.
    const MeshHeader& header() const { return header_; }
    std::optional<uint64_t> triangle_count() const { return header_.triangle_count; }

protected:
    // Counts `n` more of the warning `text` (one fixed sentence per kind), keeping the
    // position of the first.
    void warn(std::string_view text, uint64_t line = 0, uint64_t byte_offset = ~uint64_t{0}, uint64_t n = 1) {
        for (ReaderWarning& w : header_.warnings)
            if (w.text == text) {
                w.count += n;
                return;
            }
        header_.warnings.push_back({std::string(text), n, line, byte_offset});
    }

    MeshHeader header_;
};

class Writer {
public:
    virtual ~Writer() = default;
    // Consumes one chunk. Throws io::Error; std::logic_error after finish().
    void write(const TriangleChunk& chunk) {
        if (finished_) throw std::logic_error("io::Writer::write after finish()");
        write_chunk(chunk);
    }
    // Completes the output (footer, header counts), once (std::logic_error the second time).
    // The caller then commits the ByteSink; a writer destroyed without finish() leaves output
    // that is discarded.
    void finish() {
        if (finished_) throw std::logic_error("io::Writer::finish called twice");
        finished_ = true;
        finish_output();
    }
    // Before finish(): the stream's material table as it stands at the end of the input, when
    // the reader added to it while reading (MeshHeader::materials); it begins with
    // WriteOptions::materials. Writers that keep the material channel take it; std::logic_error
    // after finish().
    void update_materials(const std::vector<Material>& materials) {
        if (finished_) throw std::logic_error("io::Writer::update_materials after finish()");
        materials_updated(materials);
    }
    // After finish(): what the user should know about the output written (lossy encodings
    // that lost something), one sentence each, its settings in io::setting_words.
    std::vector<std::string> notes() const {
        std::vector<std::string> out = raw_notes();
        for (std::string& note : out) note = render(note);
        return out;
    }
    // The same with the settings' mentions kept (io::mention), for a caller that names them in
    // its own words (the commands print them as warnings, with their flags).
    std::vector<std::string> raw_notes() const { return format_notes(); }

protected:
    // The format's notes (raw_notes()).
    virtual std::vector<std::string> format_notes() const { return {}; }
    // What each format does: the calls above, checked.
    virtual void write_chunk(const TriangleChunk& chunk) = 0;
    virtual void finish_output() = 0;
    // Writers that keep materials replace their table with this one (see update_materials).
    virtual void materials_updated(const std::vector<Material>& materials) { (void)materials; }

private:
    bool finished_ = false;
};

// The memory budget of streaming work when the caller gives none (256 MiB): the tables of the
// indexed formats, sort runs, spills, edge counting.
inline constexpr uint64_t kDefaultMemoryBudget = uint64_t{256} << 20;

struct ReadOptions {
    uint64_t memory_budget_bytes = kDefaultMemoryBudget;  // spill indexed tables past this
    std::string tmpdir;                                  // empty: system temp dir
    bool strict = false;                                 // --strict: skip-with-warning becomes error
    // The kinds of channel the caller's chunks will have. Readers that keep vertices (PLY)
    // store only these, so a positions-only consumer (decimate, info) pays nothing for a
    // coloured file's colours. header().channels still lists all the file carries; a chunk
    // channel of a kind not wanted is left at its default.
    ChannelKinds channels;
};

// Options that belong to one format (io/draco.hpp's DracoSettings, io/gltf.hpp's
// GltfSettings): each a small struct that its format defines, documents and checks, held here
// at most once per type. The generic code carries them without looking inside; a writer reads
// its own with get<T>(), which gives T's defaults when none was set, and ignores the others.
class FormatOptions {
public:
    // Sets the options of type T, replacing any set before.
    template <class T>
    void set(T value) {
        for (std::any& entry : entries_)
            if (T* held = std::any_cast<T>(&entry)) {
                *held = std::move(value);
                return;
            }
        entries_.emplace_back(std::move(value));
    }
    // The options of type T that were set, else T's defaults.
    template <class T>
    T get() const {
        for (const std::any& entry : entries_)
            if (const T* held = std::any_cast<T>(&entry)) return *held;
        return T{};
    }

private:
    std::vector<std::any> entries_;  // at most one of each type
};

struct WriteOptions {
    uint64_t memory_budget_bytes = kDefaultMemoryBudget;  // for writers that weld or spool
    // The budget is --memory divided by this (sort gives its writer a quarter): the --memory a
    // budget error asks for is the bytes needed times this.
    uint32_t memory_budget_divisor = 1;
    std::string tmpdir;
    std::optional<uint64_t> triangle_count;  // total to be written, when known up front
    // About how many triangles will be written, when known before any are (an input header's
    // count, decimate's target): whole-mesh writers (Draco, glTF) then refuse a memory budget
    // that cannot hold them at once, instead of failing part way through a long run.
    std::optional<uint64_t> expected_triangle_count;
    std::optional<int> sorted_axis;  // recorded in the header when the format has room
    std::string comment;             // free text for formats with comments
    // --strict: a writer that cannot hold something it is given (a degenerate triangle Draco
    // drops, a NaN no quantization holds) throws io::Error instead of a counted note.
    bool strict = false;
    // The stream's channels: every chunk written has exactly these (the command chooses them
    // with Format::keep_channels), and the material table their material channel indexes.
    Channels channels;
    std::vector<Material> materials;
    // Add area-weighted smooth normals to a mesh without normals of its own, where the format
    // can (--normals: Draco, glTF).
    bool normals = false;
    // Options of one format only (Draco's quantization, glTF's compression); see FormatOptions.
    FormatOptions format_options;
};

struct Format {
    std::string_view name;         // as open_input and open_output take it: "stl", "stl-ascii", "ply", ...
    std::string_view extensions;   // space separated, lower case, without dot: "stl"
    std::string_view description;  // one line for listings and docs
    // True when `head` (the first bytes, up to 4 KiB) is this format. `file_size` is the
    // decoded size when known. May be null (never detected by content).
    bool (*probe)(std::span<const std::byte> head, std::optional<uint64_t> file_size);
    // May be null (write-only format). Throws io::Error.
    std::unique_ptr<Reader> (*open_reader)(ByteSource& source, const ReadOptions& options);
    // May be null (read-only format). Throws io::Error.
    std::unique_ptr<Writer> (*open_writer)(ByteSink& sink, const WriteOptions& options);
    // What the writer keeps or does beyond positions, for the commands' checks and warnings.
    enum Trait : uint8_t {
        kWholeMesh = 1,  // the writer holds the whole mesh until finish (WholeMeshBudget)
    };
    uint8_t traits = 0;
    // For formats without magic bytes: a weaker test, tried only when no probe and no
    // extension identify the input. May be null.
    bool (*guess)(std::span<const std::byte> head) = nullptr;
    // Of the channels `in`, those the writer keeps (with the options it will be given: glTF
    // with Draco keeps fewer). Null: positions only (vertex ids are a hint, never "kept").
    Channels (*keep_channels)(const Channels& in, const WriteOptions& options) = nullptr;
    // The files the writer creates or replaces beside an output at `path` (a .gltf's .bin),
    // so the commands can refuse an output that would overwrite an input. Null: none.
    std::vector<std::string> (*side_files)(const std::string& path, const WriteOptions& options) = nullptr;
    // Why the writer, with `options`, does not keep the order of the triangles it is given
    // ("Draco compression reorders triangles"), so that a sorted stream would lose its order;
    // empty when it keeps it (at least for a stream sorted along WriteOptions::sorted_axis).
    // Null: it keeps the order.
    std::string (*reorders_triangles)(const WriteOptions& options) = nullptr;
    // For a writer that keeps a sorted order but has no place to record
    // WriteOptions::sorted_axis: why, for the sort command's warning ("glTF has no place for
    // the sorted axis"). Empty: the file records the axis (or the order is lost anyway).
    std::string_view sorted_axis_unrecorded = {};
    // True when the writer, with `options`, reads the format options of `type` (a struct kept
    // in WriteOptions::format_options), for the commands' warnings about options that do
    // nothing. Null: it reads none.
    bool (*takes_options)(const std::type_info& type, const WriteOptions& options) = nullptr;
};

// All registered formats, in probe priority order.
std::span<const Format* const> formats();
// "draco, glb, ..." of the formats that can be read (or written), for messages.
std::string format_names(bool for_writing);
// The format named `name` (exact, case-sensitive), else the first claiming it as an extension
// ("drc"), or null.
const Format* find_format(std::string_view name);
// The first readable format whose extension matches `path` (".gz" stripped), or null.
const Format* format_for_extension(std::string_view path, bool for_writing);
// Detection for reading: magic bytes first, then the extension. Throws io::Error naming the
// file when neither identifies a readable format.
const Format& detect_input_format(ByteSource& source);
// The channels of `in` that `format` writes (none when it has no keep_channels).
Channels writable_channels(const Format& format, const Channels& in, const WriteOptions& options);
// For writing: by extension (".gz" stripped). Throws io::Error when unknown.
const Format& detect_output_format(const std::string& path);
// True when an output path asks for gzip (ends in ".gz").
bool wants_gzip(std::string_view path);

// An opened input: the byte source and its reader (reader destroyed first).
struct Input {
    std::unique_ptr<ByteSource> source;
    std::unique_ptr<Reader> reader;
    const Format* format = nullptr;
};
// Opens `path` ("-" = stdin) with the format `from` (empty: detect). Throws io::Error.
Input open_input(const std::string& path, std::string_view from = {}, const ReadOptions& options = {});

// An opened output. finish() completes the writer and renames the file into place; if it is
// destroyed without finish(), nothing is left under the target name.
struct Output {
    std::unique_ptr<ByteSink> sink;
    std::unique_ptr<Writer> writer;
    const Format* format = nullptr;
    void write(const TriangleChunk& chunk) { writer->write(chunk); }
    void finish() {
        writer->finish();
        sink->commit();
    }
};
// The format open_output(path, to, ...) writes. Throws io::Error as open_output does.
const Format& output_format(const std::string& path, std::string_view to);
// Opens `path` ("-" = stdout) as format `to` (empty: by extension). gzip_level applies when
// the path ends in ".gz" (or always when force_gzip). Throws io::Error.
Output open_output(const std::string& path, std::string_view to, const WriteOptions& options, int gzip_level = 6,
                   bool force_gzip = false);

}  // namespace meshstream::io
