// The only list of formats, and detection: magic bytes first, then the extension.
// Order is probe priority: formats with unambiguous magic first, STL (which has none) last.
#include "io/error.hpp"
#include "io/format.hpp"
#include "io/obj.hpp"
#include "io/ply.hpp"
#include "io/stl.hpp"
#include "io/triangle_stream.hpp"
#if MESHSTREAM_WITH_DRACO
#include "io/draco.hpp"
#endif
#if MESHSTREAM_WITH_GLTF
#include "io/gltf.hpp"
#endif

#include <algorithm>
#include <cctype>

namespace meshstream::io {
namespace {

constexpr const Format* kFormats[] = {
#if MESHSTREAM_WITH_DRACO
    &kDracoFormat,
#endif
#if MESHSTREAM_WITH_GLTF
    &kGlbFormat,   &kGltfFormat,
#endif
    &kPlyFormat,   &kPlyAsciiFormat, &kObjFormat, &kTriangleStreamFormat, &kStlFormat, &kStlAsciiFormat,
};

std::string lower(std::string_view s) {
    std::string out(s);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

// Extension of the path's last component, lower case, with a trailing ".gz" removed.
std::string extension_of(std::string_view path) {
    std::string p =
        lower(path.substr(path.find_last_of('/') == std::string_view::npos ? 0 : path.find_last_of('/') + 1));
    if (p.size() > 3 && p.ends_with(".gz")) p.resize(p.size() - 3);
    size_t dot = p.find_last_of('.');
    return dot == std::string::npos ? std::string() : p.substr(dot + 1);
}

bool has_extension(const Format& f, const std::string& ext) {
    std::string_view list = f.extensions;
    while (!list.empty()) {
        size_t sp = list.find(' ');
        std::string_view e = list.substr(0, sp);
        if (e == ext) return true;
        if (sp == std::string_view::npos) break;
        list.remove_prefix(sp + 1);
    }
    return false;
}

}  // namespace

std::string warning_position(const ReaderWarning& warning) {
    const bool line = warning.first_line != 0, byte = warning.first_byte_offset != ~uint64_t{0};
    if (!line && !byte) return {};
    std::string out = warning.count > 1 ? " (first at " : " (at ";
    if (line) out += "line " + std::to_string(warning.first_line);
    if (line && byte) out += ", ";
    if (byte) out += "byte " + std::to_string(warning.first_byte_offset);
    out += ')';
    return out;
}

std::string describe_warning(const std::string& file, const ReaderWarning& warning) {
    return (file.empty() ? std::string("<input>") : file) + ": " + warning.text + warning_position(warning);
}

std::string format_names(bool for_writing) {
    std::string out;
    for (const Format* f : kFormats) {
        if (for_writing ? !f->open_writer : !f->open_reader) continue;
        if (!out.empty()) out += ", ";
        out += f->name;
    }
    return out;
}

std::span<const Format* const> formats() { return kFormats; }

const Format* find_format(std::string_view name) {
    for (const Format* f : kFormats)
        if (f->name == name) return f;
    // An extension names its format too ("drc" is draco), the first that claims it.
    for (const Format* f : kFormats)
        if (has_extension(*f, std::string(name))) return f;
    return nullptr;
}

const Format* format_for_extension(std::string_view path, bool for_writing) {
    std::string ext = extension_of(path);
    if (ext.empty()) return nullptr;
    for (const Format* f : kFormats) {
        if (for_writing ? !f->open_writer : !f->open_reader) continue;
        if (has_extension(*f, ext)) return f;
    }
    return nullptr;
}

const Format& detect_input_format(ByteSource& source) {
    auto head = source.peek(4096);
    for (const Format* f : kFormats)
        if (f->open_reader && f->probe && f->probe(head, source.size())) return *f;
    if (const Format* f = format_for_extension(source.name(), false)) return *f;
    for (const Format* f : kFormats)
        if (f->open_reader && f->guess && f->guess(head)) return *f;
    if (head.empty()) throw Error(source.name(), "file is empty");
    throw Error(source.name(), "unrecognised format (no known magic bytes or extension; use " + mention(Setting::kFrom) + ", one of: " +
                                   format_names(false) + ")");
}

Channels writable_channels(const Format& format, const Channels& in, const WriteOptions& options) {
    Channels out = format.keep_channels ? format.keep_channels(in, options) : Channels{};
    out.vertex_id = in.vertex_id;
    return out;
}

const Format& detect_output_format(const std::string& path) {
    if (const Format* f = format_for_extension(path, true)) return *f;
    throw Error(path, "cannot tell the output format from the name (use " + mention(Setting::kTo) + ", one of: " + format_names(true) + ")");
}

bool wants_gzip(std::string_view path) { return lower(path).ends_with(".gz"); }

Input open_input(const std::string& path, std::string_view from, const ReadOptions& options) {
    Input in;
    in.source = ByteSource::open(path);
    if (!from.empty()) {
        in.format = find_format(from);
        if (!in.format || !in.format->open_reader)
            throw Error(path, "unknown input format '" + std::string(from) + "' (one of: " + format_names(false) + ")");
        in.reader = in.format->open_reader(*in.source, options);
        return in;
    }
    in.format = &detect_input_format(*in.source);
    // Chosen by its extension, a file whose content another format's guess takes (OBJ text
    // named .stl) fails in the named format's reader: the error says what else it reads as.
    const Format* guessed = nullptr;
    const auto head = in.source->peek(4096);
    for (const Format* f : kFormats)
        if (!guessed && f != in.format && f->open_reader && f->guess && f->guess(head)) guessed = f;
    try {
        in.reader = in.format->open_reader(*in.source, options);
    } catch (const Error& e) {
        if (!guessed) throw;
        throw Error(e.file(), e.byte_offset(), e.line(),
                    e.raw_message() + "; its content reads as " + std::string(guessed->name) + " (" + mention(Setting::kFrom) + " " +
                        std::string(guessed->name) + ")");
    }
    return in;
}

const Format& output_format(const std::string& path, std::string_view to) {
    if (!to.empty()) {
        const Format* f = find_format(to);
        if (!f || !f->open_writer)
            throw Error(path, "unknown output format '" + std::string(to) + "' (one of: " + format_names(true) + ")");
        return *f;
    }
    if (path == "-") throw Error("<stdout>", "writing to stdout needs " + mention(Setting::kTo) + " (one of: " + format_names(true) + ")");
    return detect_output_format(path);
}

Output open_output(const std::string& path, std::string_view to, const WriteOptions& options, int gzip_level,
                   bool force_gzip) {
    Output out;
    out.format = &output_format(path, to);
    SinkOptions sink_options;
    if (force_gzip || (path != "-" && wants_gzip(path))) sink_options.gzip_level = gzip_level;
    out.sink = ByteSink::open(path, sink_options);
    out.writer = out.format->open_writer(*out.sink, options);
    return out;
}

}  // namespace meshstream::io
