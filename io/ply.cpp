// PLY reader and writer. The header is parsed line by line (CRLF and trailing blanks allowed);
// the body is decoded from the ByteSource's window with explicit byte-order helpers (binary) or
// as blank-separated tokens in the text grammar of io/text_tokens.hpp (ascii), the way miniply
// walks its refill buffer. Based on Greg Turk's PLY description and the quirks seen in PDAL's
// PlyReader and happly: type aliases (float32, uint8, ...), `vertex_index` as well as
// `vertex_indices`, elements in any order around vertex and face. Without a face element, a `tristrips` element
// (old Stanford scans: one list of vertex indices per strip, -1 restarting) is read instead.
// Property names follow what the common writers use: MeshLab/VCG (texture_u, quality), Blender
// (s, t), PCL (normal_x), CGAL and Open3D (nx, red).
#include "io/ply.hpp"

#include "io/endian.hpp"
#include "io/error.hpp"
#include "io/line_reader.hpp"
#include "io/text_number.hpp"
#include "io/text_tokens.hpp"
#include "io/vertex_table.hpp"
#include "io/weld.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace meshstream::io {
namespace {

constexpr std::string_view kSortMarker = "meshstream sorted-axis=";
constexpr size_t kMaxTokenBytes = 4096;

bool is_float_type(ScalarType t) { return t == ScalarType::kFloat32 || t == ScalarType::kFloat64; }

std::optional<ScalarType> type_from_name(std::string_view s) {
    if (s == "char" || s == "int8") return ScalarType::kInt8;
    if (s == "uchar" || s == "uint8") return ScalarType::kUInt8;
    if (s == "short" || s == "int16") return ScalarType::kInt16;
    if (s == "ushort" || s == "uint16") return ScalarType::kUInt16;
    if (s == "int" || s == "int32") return ScalarType::kInt32;
    if (s == "uint" || s == "uint32") return ScalarType::kUInt32;
    if (s == "float" || s == "float32") return ScalarType::kFloat32;
    if (s == "double" || s == "float64") return ScalarType::kFloat64;
    return std::nullopt;
}

enum class Encoding { kAscii, kBinaryLittle, kBinaryBig };

// Where a property's values go.
struct Target {
    enum Kind : uint8_t { kSkip, kPosition, kNormal, kColor, kUv, kVertexScalar, kFaceIndices, kFaceScalar };
    Kind kind = kSkip;
    uint8_t component = 0;  // axis, colour component (RGBA) or u/v
    uint16_t index = 0;     // uv set, or scalar channel
};

struct Property {
    std::string name;
    ScalarType type = ScalarType::kFloat32;
    bool is_list = false;
    ScalarType count_type = ScalarType::kUInt8;
    Target target;  // what the reader does with it
};

struct Element {
    std::string name;
    uint64_t count = 0;
    std::vector<Property> props;
    // Bytes per item in binary when no property is a list, else 0.
    size_t fixed_bytes() const {
        size_t n = 0;
        for (const Property& p : props) {
            if (p.is_list) return 0;
            n += scalar_type_bytes(p.type);
        }
        return n;
    }
};

std::vector<std::string_view> split_words(std::string_view line) {
    std::vector<std::string_view> words;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && is_blank(line[i])) ++i;
        size_t start = i;
        while (i < line.size() && !is_blank(line[i])) ++i;
        if (i > start) words.push_back(line.substr(start, i - start));
    }
    return words;
}

// How colour properties of type t travel: uchar as value / 255 (PLY's convention), ushort as
// value / 65535, float and double as they are. Other types are no colour (nullopt): their
// properties are kept as named scalars, in their own type.
std::optional<ColorFormat> color_format(ScalarType t, bool alpha) {
    if (is_float_type(t)) return ColorFormat{ScalarType::kFloat32, alpha};
    if (t == ScalarType::kUInt16) return ColorFormat{ScalarType::kUInt16, alpha};
    if (t == ScalarType::kUInt8) return ColorFormat{ScalarType::kUInt8, alpha};
    return std::nullopt;
}

float to_color(double v, ScalarType t) {
    if (t == ScalarType::kFloat32) return static_cast<float>(v);
    return static_cast<float>(v / (t == ScalarType::kUInt16 ? 65535.0 : 255.0));
}

// The names uv set 0 is read from, in order of preference: MeshLab's explicit texture_u wins
// over Blender's s/t and the bare u/v when a file has several pairs (the others stay scalars).
constexpr std::pair<std::string_view, std::string_view> kUvNames[] = {
    {"texture_u", "texture_v"}, {"texture_s", "texture_t"}, {"u", "v"}, {"s", "t"}};

// The name the writer gives uv set `set`'s u (or v) and the reader reads sets 1.. from.
std::string uv_name(int set, int component) {
    std::string name = component == 0 ? "texture_u" : "texture_v";
    if (set > 0) name += std::to_string(set);
    return name;
}

// "float x y z nx ny nz, uchar red green blue, list uchar int vertex_indices": an element's
// properties for `info`, consecutive ones of one type grouped.
std::string describe_properties(const Element& e) {
    std::string out;
    for (size_t p = 0; p < e.props.size(); ++p) {
        const Property& prop = e.props[p];
        const bool same = p > 0 && !prop.is_list && !e.props[p - 1].is_list && e.props[p - 1].type == prop.type;
        if (same) {
            out += ' ';
        } else {
            if (p > 0) out += ", ";
            if (prop.is_list) {
                out += "list ";
                out += scalar_type_name(prop.count_type);
                out += ' ';
            }
            out += scalar_type_name(prop.type);
            out += ' ';
        }
        out += printable(prop.name, 64);
    }
    return out;
}

// ---------------- reader ----------------

class PlyReader : public Reader, private IndexedSource {
public:
    PlyReader(ByteSource& source, const ReadOptions& options) : src_(source), options_(options) {
        parse_header();
        read_up_to_faces();
    }

    bool next(TriangleChunk& chunk) override {
        chunk.clear();
        map_face_scalars(chunk.channels());
        for (;;) {
            if (polygon_next_ + 2 < polygon_.size()) {
                const CornerLayout* layout = layout_ ? &*layout_ : nullptr;
                const size_t before = chunk.size();
                const bool done = emit_polygon(*table_, layout, polygon_, polygon_scratch_, &polygon_next_, chunk);
                if (!face_scalar_map_.empty()) fill_face_scalars(chunk, before);
                if (!done) return true;
            }
            if (chunk.full()) return true;
            if (strip_next_ < strip_triangles_.size()) {  // the current strip, a triangle at a time
                polygon_.assign(strip_triangles_.begin() + strip_next_, strip_triangles_.begin() + strip_next_ + 3);
                polygon_next_ = 0;
                strip_next_ += 3;
                continue;
            }
            // (finish_body reads past the elements after the faces, moving element_ and item_.)
            if (face_ < 0 || body_finished_ || item_ == elements_[static_cast<size_t>(face_)].count) {
                if (chunk.empty()) finish_body();
                return !chunk.empty();
            }
            read_face();
        }
    }

    // Every corner of a PLY carries its vertex's values only: the table and the faces' indices
    // are the mesh (the table's records, when it has them, are CornerLayout(stored_)'s).
    IndexedSource* indexed() override {
        const bool untouched = item_ == 0 && polygon_.empty() && strip_triangles_.empty() && !body_finished_;
        return table_ && untouched && table_->size() <= 0xFFFFFFFFull ? this : nullptr;
    }

private:
    // ---- IndexedSource ----
    uint64_t vertex_count() const override { return table_->size(); }
    uint64_t vertex_table_bytes() const override { return table_->bytes(); }
    void vertex(uint64_t i, float* xyz, std::byte* record) override { table_->get(i, xyz, layout_ ? record : nullptr); }
    void positions(uint64_t first, uint64_t count, float* xyz) override { table_->positions(first, count, xyz); }
    void prefetch(uint64_t i) override { table_->prefetch(i); }
    std::unique_ptr<VertexLookup> split_lookup() override {
        struct Lookup final : VertexLookup {
            std::unique_ptr<VertexTable> table;
            bool records = false;  // the table's records are corner records (layout_)
            void vertex(uint64_t i, float* xyz, std::byte* record) override {
                table->get(i, xyz, records ? record : nullptr);
            }
            void prefetch(uint64_t i) override { table->prefetch(i); }
        };
        auto lookup = std::make_unique<Lookup>();
        lookup->table = table_->split();
        lookup->records = layout_.has_value();
        return lookup;
    }
    bool next_triangles(std::vector<uint32_t>& indices, size_t max) override {
        const size_t start = indices.size();
        for (;;) {
            if (strip_next_ < strip_triangles_.size()) {  // read_face queued a strip's triangles
                indices.insert(indices.end(), strip_triangles_.begin() + strip_next_, strip_triangles_.end());
                strip_next_ = strip_triangles_.size();
            }
            if (indices.size() >= start + 3 * max) return true;
            if (face_ < 0 || body_finished_ || item_ == elements_[static_cast<size_t>(face_)].count) {
                finish_body();
                return indices.size() > start;
            }
            read_face();
            const size_t n = polygon_.size();
            if (n == 3) {
                indices.insert(indices.end(), polygon_.begin(), polygon_.end());
            } else if (n > 3) {  // triangulated as emit_polygon does, on the corners' positions
                PolygonScratch& scratch = polygon_scratch_;
                scratch.xyz.resize(3 * n);
                for (size_t k = 0; k < n; ++k) table_->get(polygon_[k], &scratch.xyz[3 * k], nullptr);
                scratch.triangles.clear();
                triangulate_polygon(scratch.xyz, scratch.triangulate, scratch.triangles);
                for (const uint32_t corner : scratch.triangles) indices.push_back(static_cast<uint32_t>(polygon_[corner]));
            }
            polygon_.clear();
        }
    }

    // ---- header ----
    std::string header_line() {
        std::string_view line;
        if (!header_lines_.next(line) || header_lines_.unterminated())
            header_fail("file ends inside the header (no end_header line)");
        line_ = header_lines_.physical_lines();
        return std::string(line);
    }

    [[noreturn]] void header_fail(const std::string& message) const {
        throw Error(src_.name(), Error::kNoOffset, line_ + 1, message);
    }

    void parse_header() {
        // The magic first, from the raw bytes: random bytes are "not a PLY file", whatever a
        // line reader would say of them.
        const auto head = src_.peek(64);
        const std::string_view first(reinterpret_cast<const char*>(head.data()), head.size());
        const std::string_view magic_text = first.substr(0, 3);
        if (magic_text != std::string_view("ply").substr(0, magic_text.size()) ||
            (first.size() > 3 && !is_blank(first[3])))
            throw Error(src_.name(), 0, 0,
                        "not a PLY file (first line is " + quote_token(first.substr(0, first.find('\n'))) + ")");
        std::string magic = header_line();
        if (magic != "ply") throw Error(src_.name(), 0, 0, "not a PLY file (first line is " + quote_token(magic) + ")");
        bool have_format = false;
        // Lines that are no keyword (old Blender exporters wrote a bare "Created by Blender3D
        // 247 - www.blender.org"): skipped like comments, counted, or an error under --strict.
        uint64_t stray_lines = 0, stray_line = 0, stray_offset = 0;
        std::string stray_text;
        for (;;) {
            uint64_t line_start = src_.offset();
            std::string line = header_line();
            auto words = split_words(line);
            if (words.empty()) continue;
            std::string_view key = words[0];
            auto bad = [&](const std::string& what) {
                throw Error(src_.name(), line_start, line_, what + " in header line " + quote_token(line));
            };
            if (key == "end_header") break;
            if (key == "comment" || key == "obj_info") {
                size_t at = line.find(kSortMarker);
                if (at != std::string::npos && at + kSortMarker.size() < line.size()) {
                    char axis = line[at + kSortMarker.size()];
                    if (axis >= 'x' && axis <= 'z') header_.sorted_axis = axis - 'x';
                }
                continue;
            }
            if (key == "format") {
                if (words.size() < 2) bad("missing encoding");
                if (words[1] == "ascii")
                    encoding_ = Encoding::kAscii;
                else if (words[1] == "binary_little_endian")
                    encoding_ = Encoding::kBinaryLittle;
                else if (words[1] == "binary_big_endian")
                    encoding_ = Encoding::kBinaryBig;
                else
                    bad("unknown format " + quote_token(words[1]));
                header_.variant = std::string(words[1]);
                have_format = true;
            } else if (key == "element") {
                if (words.size() != 3) bad("expected 'element <name> <count>'");
                Element e;
                e.name = std::string(words[1]);
                if (!io::parse_integer(words[2], e.count)) bad("bad element count");
                elements_.push_back(std::move(e));
            } else if (key == "property") {
                if (elements_.empty()) bad("property before any element");
                Property prop;
                if (words.size() == 5 && words[1] == "list") {
                    auto ct = type_from_name(words[2]);
                    auto it = type_from_name(words[3]);
                    if (!ct || !it || is_float_type(*ct)) bad("bad list types");
                    prop.is_list = true;
                    prop.count_type = *ct;
                    prop.type = *it;
                    prop.name = std::string(words[4]);
                } else if (words.size() == 3) {
                    auto t = type_from_name(words[1]);
                    if (!t) bad("unknown property type " + quote_token(words[1]));
                    prop.type = *t;
                    prop.name = std::string(words[2]);
                } else {
                    bad("expected 'property <type> <name>' or 'property list <count type> <type> <name>'");
                }
                // Which x is meant when there are two? (The last one used to win silently.)
                for (const Property& before : elements_.back().props)
                    if (before.name == prop.name)
                        bad("property " + quote_token(prop.name) + " declared twice in element " +
                            quote_token(elements_.back().name));
                elements_.back().props.push_back(std::move(prop));
            } else {
                if (options_.strict) bad("unknown keyword " + quote_token(key) + " (" + mention(Setting::kStrict) + ")");
                if (stray_lines++ == 0) {
                    stray_line = line_;
                    stray_offset = line_start;
                    stray_text = "'" + printable(line, 100) + "'";
                }
            }
        }
        if (!have_format) throw Error(src_.name(), Error::kNoOffset, line_, "PLY header has no 'format' line");
        if (stray_lines > 0)
            warn("header lines that are no PLY keyword skipped like comments (the first: " + stray_text + ")",
                 stray_line, stray_offset, stray_lines);
        swap_ = (encoding_ == Encoding::kBinaryBig) == (std::endian::native == std::endian::little);

        int strips = -1;
        for (size_t i = 0; i < elements_.size(); ++i) {
            if (elements_[i].name == "vertex" && vertex_ < 0) vertex_ = static_cast<int>(i);
            if (elements_[i].name == "face" && face_ < 0) face_ = static_cast<int>(i);
            if (elements_[i].name == "tristrips" && strips < 0) strips = static_cast<int>(i);
        }
        if (face_ < 0 && strips >= 0) {
            face_ = strips;
            strips_ = true;
        }
        if (face_ >= 0) {
            const Element& f = elements_[static_cast<size_t>(face_)];
            for (size_t p = 0; p < f.props.size(); ++p)
                if (f.props[p].is_list && (f.props[p].name == "vertex_indices" || f.props[p].name == "vertex_index"))
                    index_prop_ = static_cast<int>(p);
            if (index_prop_ < 0 && f.count > 0)
                throw Error(src_.name(), Error::kNoOffset, line_,
                            f.name + " element has no list property 'vertex_indices' or 'vertex_index'");
            if (f.count > 0 && vertex_ < 0)
                throw Error(src_.name(), Error::kNoOffset, line_, "faces but no vertex element");
            if (f.count > 0 && face_ < vertex_)
                throw Error(src_.name(), Error::kNoOffset, line_,
                            "face element before the vertex element is not supported");
        }
        header_.channels.vertex_id = true;
        if (vertex_ >= 0) classify_vertex_properties();
        if (face_ >= 0) classify_face_properties();
        stored_ = options_.channels.of(header_.channels);
        face_values_.resize(header_.channels.face_scalars.size());
        // What is not read is said once, with how many items it covers.
        for (size_t i = 0; i < elements_.size(); ++i) {
            const Element& e = elements_[i];
            header_.notes.emplace_back("element " + printable(e.name, 64),
                                       std::to_string(e.count) + " × " + describe_properties(e));
            if (e.count == 0) continue;
            if (static_cast<int>(i) != vertex_ && static_cast<int>(i) != face_) {
                warn("element " + quote_token(e.name) + " not read: meshstream reads vertices and faces", 0,
                     Error::kNoOffset, e.count);
                continue;
            }
            for (const Property& p : e.props)
                if (p.is_list && p.target.kind != Target::kFaceIndices)
                    warn("list property " + quote_token(p.name) + " of element " + quote_token(e.name) + " not read", 0,
                         Error::kNoOffset, e.count);
        }
        uint64_t faces = face_ >= 0 ? elements_[static_cast<size_t>(face_)].count : 0;
        if (faces == 0) header_.triangle_count = 0;
        if (!strips_) header_.triangle_estimate = faces;
        header_.notes.emplace_back(strips_ ? "tristrips" : "faces", std::to_string(faces));
    }

    // Sets each vertex property's target and the header's per-corner channels: x, y, z;
    // nx, ny, nz (or PCL's normal_x, ...); red, green, blue (+ alpha) of one colour type;
    // uv set 0 from the first pair of kUvNames present, sets 1.. from texture_u1/texture_v1, ...;
    // every other scalar by name. Lists other than face indices are not read.
    void classify_vertex_properties() {
        Element& v = elements_[static_cast<size_t>(vertex_)];
        auto find = [&](std::string_view name) -> Property* {
            for (Property& p : v.props)
                if (!p.is_list && p.name == name && p.target.kind == Target::kSkip) return &p;
            return nullptr;
        };
        for (int a = 0; a < 3; ++a) {
            Property* p = find(std::string(1, char('x' + a)));
            if (!p)
                throw Error(src_.name(), Error::kNoOffset, line_,
                            std::string("vertex element has no property '") + char('x' + a) + "'");
            p->target = {Target::kPosition, uint8_t(a), 0};
        }
        header_.vertex_count = v.count;
        for (const auto& names : {std::array<const char*, 3>{"nx", "ny", "nz"},
                                  std::array<const char*, 3>{"normal_x", "normal_y", "normal_z"}}) {
            Property* n[3] = {find(names[0]), find(names[1]), find(names[2])};
            if (header_.channels.normal || !n[0] || !n[1] || !n[2]) continue;
            for (int a = 0; a < 3; ++a) n[a]->target = {Target::kNormal, uint8_t(a), 0};
            header_.channels.normal = true;
        }
        Property* rgba[4] = {find("red"), find("green"), find("blue"), find("alpha")};
        if (rgba[0] && rgba[1] && rgba[2] && rgba[1]->type == rgba[0]->type && rgba[2]->type == rgba[0]->type) {
            const bool alpha = rgba[3] && rgba[3]->type == rgba[0]->type;
            if (auto format = color_format(rgba[0]->type, alpha)) {
                header_.channels.color = format;
                for (int c = 0; c < (alpha ? 4 : 3); ++c) rgba[c]->target = {Target::kColor, uint8_t(c), 0};
            }
        }
        for (int set = 0; set < kMaxUvSets; ++set) {
            Property* uv[2] = {};
            if (set == 0) {
                for (const auto& [u, w] : kUvNames) {
                    uv[0] = find(u), uv[1] = find(w);
                    if (uv[0] && uv[1] && is_float_type(uv[0]->type) && is_float_type(uv[1]->type)) break;
                    uv[0] = uv[1] = nullptr;
                }
            } else {
                uv[0] = find(uv_name(set, 0)), uv[1] = find(uv_name(set, 1));
            }
            if (!uv[0] || !uv[1] || !is_float_type(uv[0]->type) || !is_float_type(uv[1]->type)) break;
            for (int c = 0; c < 2; ++c) uv[c]->target = {Target::kUv, uint8_t(c), uint16_t(set)};
            header_.channels.uv_sets = set + 1;
        }
        for (Property& p : v.props) {
            if (p.is_list || p.target.kind != Target::kSkip) continue;
            p.target = {Target::kVertexScalar, 0, uint16_t(header_.channels.vertex_scalars.size())};
            header_.channels.vertex_scalars.push_back({p.name, p.type});
        }
    }

    // The face (or tristrips) element: its index list, and every other scalar as a face scalar
    // (per-face colours too: CGAL's colored_tetra.ply has per-face red, green, blue and a label).
    void classify_face_properties() {
        Element& f = elements_[static_cast<size_t>(face_)];
        for (size_t p = 0; p < f.props.size(); ++p) {
            Property& prop = f.props[p];
            if (static_cast<int>(p) == index_prop_) {
                prop.target.kind = Target::kFaceIndices;
            } else if (!prop.is_list) {
                prop.target = {Target::kFaceScalar, 0, uint16_t(header_.channels.face_scalars.size())};
                header_.channels.face_scalars.push_back({prop.name, prop.type});
            }
        }
    }

    // ---- body primitives ----
    [[noreturn]] void item_fail(uint64_t offset, const std::string& message) const {
        const Element& e = elements_[element_];
        throw Error(src_.name(), offset, encoding_ == Encoding::kAscii ? line_ + 1 : 0,
                    "element '" + e.name + "' item " + std::to_string(item_) + ": " + message);
    }

    [[noreturn]] void truncated() const {
        const Element& e = elements_[element_];
        item_fail(src_.offset(),
                  "file ends early (header promises " + std::to_string(e.count) + " " + e.name + " items)");
    }

    const std::byte* need(size_t n) {
        auto s = src_.peek(n);
        if (s.size() < n) truncated();
        return s.data();
    }

    template <class U>
    U load(const std::byte* p) const {
        U v;
        std::memcpy(&v, p, sizeof v);
        return swap_ ? byteswap(v) : v;
    }

    double decode(const std::byte* p, ScalarType t) const {
        switch (t) {
            case ScalarType::kInt8: return load<int8_t>(p);
            case ScalarType::kUInt8: return load<uint8_t>(p);
            case ScalarType::kInt16: return load<int16_t>(p);
            case ScalarType::kUInt16: return load<uint16_t>(p);
            case ScalarType::kInt32: return load<int32_t>(p);
            case ScalarType::kUInt32: return load<uint32_t>(p);
            case ScalarType::kFloat32: return load<float>(p);
            case ScalarType::kFloat64: return load<double>(p);
        }
        return 0;
    }

    int64_t decode_int(const std::byte* p, ScalarType t) const {
        switch (t) {
            case ScalarType::kInt8: return load<int8_t>(p);
            case ScalarType::kUInt8: return load<uint8_t>(p);
            case ScalarType::kInt16: return load<int16_t>(p);
            case ScalarType::kUInt16: return load<uint16_t>(p);
            case ScalarType::kInt32: return load<int32_t>(p);
            case ScalarType::kUInt32: return load<uint32_t>(p);
            case ScalarType::kFloat32: return static_cast<int64_t>(load<float>(p));
            case ScalarType::kFloat64: return static_cast<int64_t>(load<double>(p));
        }
        return 0;
    }

    // ASCII PLY holds one item per line, as every writer does. Items that share a line mean
    // the header's counts disagree with the data: a vertex count larger than the vertex lines
    // makes the last "vertices" read from the faces' numbers and shifts the faces, which can
    // otherwise come out as valid-looking garbage (when other elements follow the faces).
    void item_begins() {
        if (encoding_ == Encoding::kAscii) check_item_line_ = true;
    }
    void item_ends() {
        check_item_line_ = false;
        line_break_seen_ = false;
    }

    // Next whitespace-separated ascii token (its offset in token_offset_).
    std::string_view token() {
        for (;;) {
            auto w = src_.window();
            if (w.empty()) truncated();
            const char* p = reinterpret_cast<const char*>(w.data());
            size_t i = 0;
            while (i < w.size() && is_blank(p[i])) {
                if (p[i] <= '\r') {  // not a space: maybe a line end (CR alone too: old Mac files)
                    line_ += p[i] == '\n';
                    line_break_seen_ |= p[i] == '\n' || p[i] == '\r';
                }
                ++i;
            }
            src_.consume(i);
            if (i < w.size()) break;
        }
        auto w = src_.window();
        const char* p = reinterpret_cast<const char*>(w.data());
        size_t j = 0;
        while (j < w.size() && !is_blank(p[j])) ++j;
        if (j == w.size()) {  // the token may continue past the buffered bytes
            w = src_.peek(kMaxTokenBytes);
            p = reinterpret_cast<const char*>(w.data());
            j = 0;
            while (j < w.size() && !is_blank(p[j])) ++j;
            if (j == kMaxTokenBytes) item_fail(src_.offset(), "token longer than 4 KiB");
        }
        token_offset_ = src_.offset();
        if (check_item_line_) {
            check_item_line_ = false;
            item_first_offset_ = token_offset_;
            item_first_line_ = line_ + 1;
            if (!line_break_seen_)
                item_fail(token_offset_,
                          "begins on the line where the item before it ends: the header's element "
                          "counts disagree with the data (ascii PLY has one item a line)");
        }
        src_.consume(j);
        return {p, j};
    }

    // Ascii values by their declared type, in the text grammar (io/text_tokens.hpp): numbers
    // for float and double, integers for the integer types (a token that is no number at all
    // is "expected a number" either way).
    double parse_number(std::string_view tok) const {
        double v = 0;
        if (!io::parse_number(tok, v)) item_fail(token_offset_, "expected a number, found " + quote_token(tok));
        return v;
    }

    float parse_float(std::string_view tok) const {
        float v = 0;
        if (!io::parse_number(tok, v)) item_fail(token_offset_, "expected a number, found " + quote_token(tok));
        return v;
    }

    int64_t parse_integer(std::string_view tok, ScalarType t) const {
        int64_t v = 0;
        if (!is_float_type(t)) {
            if (io::parse_integer(tok, v)) return v;
            parse_number(tok);
            item_fail(token_offset_, "expected an integer, found " + quote_token(tok));
        }
        // A list of float indices: each an integral value.
        double d = parse_number(tok);
        if (d != std::floor(d) || !(std::fabs(d) < 9e18))
            item_fail(token_offset_, "expected an integer, found " + quote_token(tok));
        return static_cast<int64_t>(d);
    }

    double read_scalar(ScalarType t) {
        if (encoding_ == Encoding::kAscii)
            return is_float_type(t) ? parse_number(token()) : static_cast<double>(parse_integer(token(), t));
        size_t n = scalar_type_bytes(t);
        double v = decode(need(n), t);
        src_.consume(n);
        return v;
    }

    int64_t read_integer(ScalarType t) {
        if (encoding_ == Encoding::kAscii) return parse_integer(token(), t);
        size_t n = scalar_type_bytes(t);
        token_offset_ = src_.offset();
        int64_t v = decode_int(need(n), t);
        src_.consume(n);
        return v;
    }

    int64_t read_count(const Property& p) {
        int64_t n = read_integer(p.count_type);
        if (n < 0) item_fail(token_offset_, "negative list length " + std::to_string(n) + " in '" + p.name + "'");
        return n;
    }

    void skip_property(const Property& p) {
        if (!p.is_list) {
            read_scalar(p.type);
            return;
        }
        int64_t n = read_count(p);
        if (encoding_ == Encoding::kAscii) {
            for (int64_t i = 0; i < n; ++i) read_scalar(p.type);
        } else {
            uint64_t bytes = uint64_t(n) * scalar_type_bytes(p.type);
            if (src_.skip(bytes) != bytes) truncated();
        }
    }

    // A count whose byte size overflows 64 bits cannot be in any file.
    void check_size(const Element& e, size_t fixed) const {
        if (e.count > ~uint64_t{0} / fixed)
            throw Error(src_.name(), src_.offset(), 0,
                        "element '" + e.name + "': header promises " + std::to_string(e.count) +
                            " items, more than any file holds");
    }

    void skip_element(size_t index) {
        element_ = index;
        const Element& e = elements_[index];
        size_t fixed = e.fixed_bytes();
        if (encoding_ != Encoding::kAscii && fixed > 0) {
            check_size(e, fixed);
            uint64_t bytes = e.count * fixed;
            uint64_t got = src_.skip(bytes);
            if (got != bytes) {
                item_ = got / fixed;
                truncated();
            }
            item_ = e.count;
            return;
        }
        for (item_ = 0; item_ < e.count; ++item_) {
            item_begins();
            for (const Property& p : e.props) skip_property(p);
            item_ends();
        }
    }

    // ---- vertices ----
    // Reads (or skips) the elements before the faces; the faces then stream from next().
    void read_up_to_faces() {
        for (size_t i = 0; i < elements_.size(); ++i) {
            element_ = i;
            item_ = 0;
            if (static_cast<int>(i) == face_) {
                // Binary triangles of one index list of integers: prefetch_ahead() can find them.
                const Element& f = elements_[i];
                if (encoding_ != Encoding::kAscii && !strips_ && table_ && f.props.size() == 1 &&
                    f.props[0].is_list && !is_float_type(f.props[0].type) && index_prop_ == 0)
                    face_bytes_ = scalar_type_bytes(f.props[0].count_type) + 3 * scalar_type_bytes(f.props[0].type);
                return;
            }
            if (static_cast<int>(i) == vertex_) {
                read_vertices(i);
                if (face_ < 0) return;  // a point cloud: nothing more to read
            } else {
                skip_element(i);
            }
        }
    }

    // True when the caller wants the channel a vertex property feeds (ReadOptions::channels).
    bool stored(const Target& t) const {
        switch (t.kind) {
            case Target::kPosition: return true;
            case Target::kNormal: return stored_.normal;
            case Target::kColor: return stored_.color.has_value();
            case Target::kUv: return t.index < stored_.uv_sets;
            case Target::kVertexScalar: return !stored_.vertex_scalars.empty();
            default: return false;
        }
    }

    void read_vertices(size_t index) {
        element_ = index;
        const Element& e = elements_[index];
        size_t fixed = e.fixed_bytes();
        const uint64_t budget = options_.memory_budget_bytes;
        const CornerLayout layout(stored_);
        // A plain file in host byte order with float x, y, z, of which the caller wants no
        // attribute, is read in place: whatever else its vertices hold costs nothing.
        bool direct = encoding_ != Encoding::kAscii && !swap_ && fixed > 0 && !src_.regular_file_path().empty() &&
                      layout.bytes() == 0;
        // The properties read, with their offset in a fixed-size binary record.
        struct Read {
            size_t offset;
            ScalarType type;
            Target target;
        };
        std::vector<Read> reads;
        size_t xyz_offsets[3] = {};
        size_t offset = 0;
        for (const Property& p : e.props) {
            if (stored(p.target)) reads.push_back({offset, p.type, p.target});
            if (p.target.kind == Target::kPosition) {
                xyz_offsets[p.target.component] = offset;
                if (p.type != ScalarType::kFloat32) direct = false;
            }
            offset += p.is_list ? 0 : scalar_type_bytes(p.type);
        }
        if (fixed > 0 && encoding_ != Encoding::kAscii) check_size(e, fixed);
        if (direct) {
            uint64_t start = src_.offset();
            uint64_t bytes = e.count * fixed;
            uint64_t got = src_.skip(bytes);  // also proves the block is all there
            if (got != bytes) {
                item_ = got / fixed;
                truncated();
            }
            table_ = VertexTable::of_input_file(src_.regular_file_path(), start, e.count, fixed, xyz_offsets, budget);
            header_.notes.emplace_back("vertex table", "input file, read in place");
            return;
        }
        table_ = std::make_unique<VertexTable>(budget, options_.tmpdir, layout.bytes());
        if (layout.bytes() > 0) layout_ = layout;
        // meshstream's chunks hold float coordinates: double ones are rounded, which far from
        // the origin moves them by a lot (0.25 m at 4 000 000); the largest change is said.
        bool doubles = false;
        for (const Property& p : e.props)
            doubles |= p.target.kind == Target::kPosition && p.type == ScalarType::kFloat64;
        const ScalarType color_type = stored_.color ? stored_.color->type : ScalarType::kUInt8;
        double worst_rounding = 0, worst_at = 0;
        double position[3] = {0, 0, 0};
        float xyz[3];
        float normal[3] = {0, 0, 0};
        float rgba[4] = {0, 0, 0, 1};
        float uv[2 * kMaxUvSets] = {};
        std::vector<double> scalars(stored_.vertex_scalars.size());
        std::vector<std::byte> record(layout.bytes());
        auto assign = [&](const Target& t, double v) {
            switch (t.kind) {
                case Target::kPosition: position[t.component] = v; break;
                case Target::kNormal: normal[t.component] = static_cast<float>(v); break;
                case Target::kColor: rgba[t.component] = to_color(v, color_type); break;
                case Target::kUv: uv[2 * t.index + t.component] = static_cast<float>(v); break;
                case Target::kVertexScalar: scalars[t.index] = v; break;
                default: break;
            }
        };
        for (item_ = 0; item_ < e.count; ++item_) {
            if (fixed > 0 && encoding_ != Encoding::kAscii) {
                const std::byte* rec = need(fixed);
                for (const Read& r : reads) assign(r.target, decode(rec + r.offset, r.type));
                src_.consume(fixed);
                for (int a = 0; a < 3; ++a) xyz[a] = static_cast<float>(position[a]);
            } else {
                item_begins();
                for (const Property& prop : e.props) {
                    if (!stored(prop.target)) {
                        skip_property(prop);
                    } else if (prop.target.kind == Target::kPosition && encoding_ == Encoding::kAscii &&
                               prop.type != ScalarType::kFloat64) {
                        // decimal -> float directly: no double rounding
                        xyz[prop.target.component] = parse_float(token());
                        position[prop.target.component] = xyz[prop.target.component];
                    } else {
                        assign(prop.target, read_scalar(prop.type));
                        if (prop.target.kind == Target::kPosition)
                            xyz[prop.target.component] = static_cast<float>(position[prop.target.component]);
                    }
                }
                item_ends();
            }
            if (doubles)
                for (int a = 0; a < 3; ++a)
                    if (std::fabs(double(xyz[a]) - position[a]) > worst_rounding) {
                        worst_rounding = std::fabs(double(xyz[a]) - position[a]);
                        worst_at = position[a];
                    }
            if (!record.empty()) layout.pack_values(normal, rgba, uv, scalars.data(), record.data());
            table_->append(xyz, record.data());
        }
        header_.notes.emplace_back("vertex table",
                                   table_->storage() == VertexTable::Storage::kMemory ? "in memory" : "temporary file");
        if (doubles) {
            std::string text = "double, rounded to float: moved by up to ";
            append_number(text, static_cast<float>(worst_rounding));
            if (worst_rounding > 0) {
                text += " (at ";
                append_number(text, worst_at);
                text += ")";
            }
            header_.notes.emplace_back(kPrecisionNote, text);
            header_.coordinate_rounding = static_cast<float>(worst_rounding);  // as the note prints it
        }
    }

    // ---- faces ----
    void read_face() {
        const Element& e = elements_[static_cast<size_t>(face_)];
        if (face_bytes_ > 0) prefetch_ahead();
        polygon_.clear();
        polygon_next_ = 0;
        const uint64_t item_offset = src_.offset();  // binary: the face's first byte
        item_begins();
        int64_t corners = 0;
        for (const Property& prop : e.props) {
            switch (prop.target.kind) {
                case Target::kFaceIndices: corners = read_indices(prop); break;
                case Target::kFaceScalar:
                    if (!stored_.face_scalars.empty()) {
                        face_values_[prop.target.index] = read_scalar(prop.type);
                        break;
                    }
                    [[fallthrough]];
                default: skip_property(prop);
            }
        }
        item_ends();
        if (!strips_ && corners < 3) few_corners(corners, item_offset);
        ++item_;
    }

    // The vertices of the face kPrefetchFaces ahead, when a binary face element holds nothing
    // but the index list and that face, read as a triangle, is one (a guess: faces of other
    // sizes before it misplace it, and a wrong guess costs a few loads): asked of the vertex
    // table ahead, so that its lookups overlap instead of each waiting for memory.
    void prefetch_ahead() {
        constexpr size_t kPrefetchFaces = 8;
        const std::span<const std::byte> ahead = src_.peek(face_bytes_ * (kPrefetchFaces + 1));
        if (ahead.size() < face_bytes_ * (kPrefetchFaces + 1)) return;
        const Property& p = elements_[static_cast<size_t>(face_)].props[0];
        const std::byte* face = ahead.data() + face_bytes_ * kPrefetchFaces;
        if (decode_int(face, p.count_type) != 3) return;
        const size_t count_bytes = scalar_type_bytes(p.count_type), index_bytes = scalar_type_bytes(p.type);
        for (size_t k = 0; k < 3; ++k) {
            const int64_t v = decode_int(face + count_bytes + k * index_bytes, p.type);
            if (v >= 0 && static_cast<uint64_t>(v) < table_->size()) table_->prefetch(static_cast<uint64_t>(v));
        }
    }

    // Reads a face's index list into polygon_ (a strip's into strip_triangles_); returns its length.
    int64_t read_indices(const Property& prop) {
        const int64_t corners = read_count(prop);
        const uint64_t vertices = table_->size();
        for (int64_t k = 0; k < corners; ++k) {
            int64_t index = read_integer(prop.type);
            if (strips_ && index == -1) {  // restart
                strip_to_triangles();
                continue;
            }
            if (index < 0 || static_cast<uint64_t>(index) >= vertices)
                item_fail(token_offset_, "vertex index " + std::to_string(index) + " out of range (" +
                                             std::to_string(vertices) + " vertices)");
            polygon_.push_back(static_cast<uint64_t>(index));
        }
        if (strips_) strip_to_triangles();
        return corners;
    }

    // A face of fewer than 3 vertices (at `item_offset` in binary; ascii: its first token):
    // skipped and counted, or an error.
    void few_corners(int64_t corners, uint64_t item_offset) {
        const Element& e = elements_[static_cast<size_t>(face_)];
        const bool ascii = encoding_ == Encoding::kAscii;
        const uint64_t offset = ascii ? item_first_offset_ : item_offset, line = ascii ? item_first_line_ : 0;
        // A binary header promising k vertices more than present makes the vertex block end k
        // records into the faces, where small meshes have zero bytes (the high bytes of
        // indices): the first "face" has no vertex, and the read realigns after a few such
        // faces, so that every count adds up. A first face of fewer than 3 vertices right after
        // the vertices is that signature (no writer starts with one).
        if (item_ == 0 && !ascii && face_ == vertex_ + 1)
            throw Error(src_.name(), offset, 0,
                        "element '" + e.name + "' item 0: the first face has " + std::to_string(corners) +
                            " vertices: the header's vertex count (" + std::to_string(table_->size()) +
                            ") is likely larger than the vertices present, and the faces read from the wrong bytes");
        if (options_.strict)
            throw Error(src_.name(), offset, line,
                        "element '" + e.name + "' item " + std::to_string(item_) + ": face with " +
                            std::to_string(corners) + " vertices (" + mention(Setting::kStrict) + ")");
        warn("faces with fewer than 3 vertices skipped", line, offset);
    }

    // Which of the stored face scalars each of the chunk's face scalars is (by name; -1: none).
    void map_face_scalars(const Channels& channels) {
        if (channels.face_scalars == mapped_face_scalars_) return;
        mapped_face_scalars_ = channels.face_scalars;
        face_scalar_map_.assign(channels.face_scalars.size(), -1);
        for (size_t c = 0; c < channels.face_scalars.size(); ++c)
            for (size_t s = 0; s < stored_.face_scalars.size(); ++s)
                if (stored_.face_scalars[s].name == channels.face_scalars[c].name) face_scalar_map_[c] = int(s);
    }

    // The current face's scalars into triangles [first, size()) of the chunk.
    void fill_face_scalars(TriangleChunk& chunk, size_t first) const {
        for (size_t c = 0; c < face_scalar_map_.size(); ++c) {
            const int s = face_scalar_map_[c];
            if (s < 0) continue;
            for (size_t t = first; t < chunk.size(); ++t) *chunk.face_scalar_at(t, c) = face_values_[size_t(s)];
        }
    }

    // Turns the strip gathered in polygon_ into triangles (every other one flipped, so all
    // keep the first one's orientation) queued in strip_triangles_; the triangles with a
    // repeated index that join strips are stitching, not surface, and are dropped.
    void strip_to_triangles() {
        if (strip_next_ == strip_triangles_.size()) strip_triangles_.clear(), strip_next_ = 0;
        for (size_t i = 0; i + 2 < polygon_.size(); ++i) {
            uint64_t a = polygon_[i], b = polygon_[i + 1];
            const uint64_t c = polygon_[i + 2];
            if (i % 2 == 1) std::swap(a, b);
            if (a == b || b == c || c == a) continue;
            strip_triangles_.insert(strip_triangles_.end(), {a, b, c});
        }
        polygon_.clear();
    }

    // After the faces. Binary: the elements after them are read past, and every byte of the
    // file must then be accounted for, so counts that disagree with the data are an error.
    // ASCII: elements after the faces are not read (real files get them wrong: CGAL's
    // colored_tetra.ply promises 3 properties per 'edge' and writes 2); the line check above
    // guards the faces. When the faces are the last element, anything but blanks after them is
    // data the header does not count (its face count is short; issue 7). In ASCII, no line end
    // after the last face is noted: a cut inside its last index ("3 9 10 1" of "3 9 10 11")
    // is otherwise a valid file.
    void finish_body() {
        if (face_ < 0 || body_finished_) return;
        body_finished_ = true;
        if (encoding_ != Encoding::kAscii)
            for (size_t i = static_cast<size_t>(face_) + 1; i < elements_.size(); ++i) skip_element(i);
        else if (static_cast<size_t>(face_) + 1 != elements_.size())
            return;
        bool line_end = false;
        for (;;) {
            auto w = src_.window();
            if (w.empty()) {
                if (encoding_ == Encoding::kAscii && item_ > 0 && !line_end)
                    header_.notes.emplace_back(kLastLineNote, kLastLineText);
                return;
            }
            const char* p = reinterpret_cast<const char*>(w.data());
            for (size_t i = 0; i < w.size(); ++i) {
                if (p[i] == '\n') {
                    ++line_;
                    line_end = true;
                } else if (!is_blank(p[i])) {
                    src_.consume(i);
                    item_fail(src_.offset(), "data after the last of the " + std::to_string(elements_[element_].count) +
                                                 " '" + elements_[element_].name + "' items the header promises");
                }
            }
            src_.consume(w.size());
        }
    }

    ByteSource& src_;
    LineReader header_lines_{src_, /*join_continuations=*/false, "header line"};
    ReadOptions options_;
    Encoding encoding_ = Encoding::kAscii;
    bool swap_ = false;
    uint64_t line_ = 0;             // lines consumed (header; ascii body)
    bool check_item_line_ = false;  // the next token begins an ascii item
    bool line_break_seen_ = true;   // since the last ascii item ended (the header ends with one)
    uint64_t item_first_offset_ = 0, item_first_line_ = 0;  // where the current ascii item begins
    bool body_finished_ = false;
    std::vector<Element> elements_;
    int vertex_ = -1, face_ = -1, index_prop_ = -1;
    Channels stored_;                     // the channels the caller wants, of those the file has
    std::optional<CornerLayout> layout_;  // the vertex table's corner records, when it has them
    size_t element_ = 0;                  // element being read (for messages)
    uint64_t item_ = 0;                   // item number within it
    uint64_t token_offset_ = 0;
    std::unique_ptr<VertexTable> table_;
    std::vector<uint64_t> polygon_;
    std::vector<double> face_values_;                 // the current face's scalars, by face scalar channel
    std::vector<ScalarChannel> mapped_face_scalars_;  // the chunk channels face_scalar_map_ is for
    std::vector<int> face_scalar_map_;
    PolygonScratch polygon_scratch_;
    size_t polygon_next_ = 0;                // next triangle of polygon_ to emit
    bool strips_ = false;                    // face_ is a tristrips element
    size_t face_bytes_ = 0;                  // a triangle's bytes, for prefetch_ahead (0: none)
    std::vector<uint64_t> strip_triangles_;  // index triples of the strips read, emitted from strip_next_
    size_t strip_next_ = 0;
};

// ---------------- writer ----------------

// A value as an integer type T stores it: rounded to nearest, clamped to T's range; NaN is 0.
template <class T>
T to_integer(double v) {
    if (!(v == v)) return 0;
    constexpr double lo = double(std::numeric_limits<T>::min()), hi = double(std::numeric_limits<T>::max());
    return static_cast<T>(std::clamp(std::nearbyint(v), lo, hi));
}

template <class T>
void put_value(std::string& out, T v, bool ascii) {
    if (ascii)
        append_number(out, v);
    else {
        char bytes[sizeof v];
        store_le(bytes, v);
        out.append(bytes, sizeof v);
    }
}

// Appends `v` as PLY type `type`: a decimal number (ascii) or little-endian bytes.
void put_scalar(std::string& out, double v, ScalarType type, bool ascii) {
    switch (type) {
        case ScalarType::kInt8: {
            const int8_t b = to_integer<int8_t>(v);
            if (ascii)
                append_number(out, int(b));  // a number, not a character
            else
                out.push_back(static_cast<char>(b));
            return;
        }
        case ScalarType::kUInt8: {
            const uint8_t b = to_integer<uint8_t>(v);
            if (ascii)
                append_number(out, unsigned(b));
            else
                out.push_back(static_cast<char>(b));
            return;
        }
        case ScalarType::kInt16: return put_value(out, to_integer<int16_t>(v), ascii);
        case ScalarType::kUInt16: return put_value(out, to_integer<uint16_t>(v), ascii);
        case ScalarType::kInt32: return put_value(out, to_integer<int32_t>(v), ascii);
        case ScalarType::kUInt32: return put_value(out, to_integer<uint32_t>(v), ascii);
        case ScalarType::kFloat32: return put_value(out, static_cast<float>(v), ascii);
        case ScalarType::kFloat64: return put_value(out, v, ascii);
    }
}

class PlyWriter : public Writer {
public:
    PlyWriter(ByteSink& sink, const WriteOptions& options, bool ascii)
        : sink_(sink),
          options_(options),
          ascii_(ascii),
          welder_(options.memory_budget_bytes, options.tmpdir, sink.name(), options.channels) {
        if (!options_.channels.face_scalars.empty())
            faces_ = std::make_unique<TempFile>(options.tmpdir, "meshstream-faces");
    }

    void write_chunk(const TriangleChunk& chunk) override {
        welder_.add(chunk);
        // Triangles leave the welder in input order: their face scalars wait in a spool.
        const size_t nf = options_.channels.face_scalars.size();
        if (nf == 0 || chunk.empty()) return;
        face_block_.resize(chunk.size() * nf);
        for (size_t t = 0; t < chunk.size(); ++t)
            for (size_t c = 0; c < nf; ++c) face_block_[t * nf + c] = *chunk.face_scalar_at(t, c);
        faces_->write(face_block_.data(), face_block_.size() * sizeof(double));
    }

    void finish_output() override {
        welder_.finish();
        const uint64_t vertices = welder_.vertex_count();
        if (vertices > 0x7fffffffULL)
            throw Error(sink_.name(),
                        "PLY int indices hold at most 2^31 - 1 vertices, the mesh has " + std::to_string(vertices));
        const Channels& ch = options_.channels;
        sink_.write(header(vertices));

        const CornerLayout& layout = welder_.layout();
        const size_t rec = layout.bytes();
        std::vector<float> xyz(3 * 8192);
        std::vector<std::byte> records(rec * 8192);
        std::string out;
        out.reserve(size_t{1} << 20);
        float normal[3], rgba[4], uv[2 * kMaxUvSets];
        std::vector<double> scalars(ch.vertex_scalars.size());
        const int color_n = ch.color ? (ch.color->alpha ? 4 : 3) : 0;
        while (size_t n = welder_.next_vertices(xyz, records)) {
            for (size_t i = 0; i < n; ++i) {
                const float* p = &xyz[3 * i];
                if (rec == 0 && !ascii_) {  // positions only: the common case, kept short
                    char buf[12];
                    for (int a = 0; a < 3; ++a) store_le(buf + 4 * a, p[a]);
                    out.append(buf, 12);
                    continue;
                }
                for (int a = 0; a < 3; ++a) put_field(out, p[a], a == 0);
                if (rec == 0) {
                    out += '\n';
                    continue;
                }
                layout.unpack_values(&records[rec * i], normal, rgba, uv, scalars.data());
                if (ch.normal)
                    for (int a = 0; a < 3; ++a) put_field(out, normal[a]);
                for (int a = 0; a < color_n; ++a) {
                    if (ascii_) out += ' ';
                    if (ch.color->type == ScalarType::kFloat32) {
                        put_value(out, rgba[a], ascii_);
                        continue;
                    }
                    const float max = ch.color->type == ScalarType::kUInt8 ? 255.0f : 65535.0f;
                    put_scalar(out, color_to_unorm<uint16_t>(rgba[a], max), ch.color->type, ascii_);
                }
                for (int a = 0; a < 2 * ch.uv_sets; ++a) put_field(out, uv[a]);
                for (size_t c = 0; c < scalars.size(); ++c) {
                    if (ascii_) out += ' ';
                    put_scalar(out, scalars[c], ch.vertex_scalars[c].type, ascii_);
                }
                if (ascii_) out += '\n';
            }
            flush(out);
        }
        const size_t nf = ch.face_scalars.size();
        std::vector<uint32_t> idx(3 * 8192);
        uint64_t triangles_done = 0;
        while (size_t n = welder_.next_indices(idx)) {
            if (nf > 0) {
                face_block_.resize(n / 3 * nf);
                faces_->read_at(triangles_done * nf * sizeof(double), face_block_.data(),
                                face_block_.size() * sizeof(double));
            }
            for (size_t t = 0; t + 2 < n; t += 3) {
                if (ascii_) {
                    out += '3';
                    for (int k = 0; k < 3; ++k) {
                        out += ' ';
                        append_number(out, idx[t + k]);
                    }
                } else {
                    char buf[13];
                    buf[0] = 3;
                    for (int k = 0; k < 3; ++k) store_le(buf + 1 + 4 * k, idx[t + k]);
                    out.append(buf, 13);
                }
                for (size_t c = 0; c < nf; ++c) {
                    if (ascii_) out += ' ';
                    put_scalar(out, face_block_[t / 3 * nf + c], ch.face_scalars[c].type, ascii_);
                }
                if (ascii_) out += '\n';
            }
            triangles_done += n / 3;
            flush(out);
        }
        flush(out);
    }

private:
    // The header: float x, y, z; float nx, ny, nz; red, green, blue (+ alpha) in the colour's
    // type; float texture_u, texture_v (set 0; texture_u1, texture_v1, ... for the next sets);
    // the vertex scalars in their types; faces as `list uchar int vertex_indices` and the face
    // scalars. Names are made unique (a scalar called "x" from another format becomes "x_2")
    // and whitespace in them becomes '_', so the header reads back.
    std::string header(uint64_t vertices) const {
        const Channels& ch = options_.channels;
        std::string h = "ply\nformat ";
        h += ascii_ ? "ascii 1.0\n" : "binary_little_endian 1.0\n";
        h += "comment generated by meshstream\n";
        if (options_.sorted_axis) h += "comment " + std::string(kSortMarker) + char('x' + *options_.sorted_axis) + "\n";
        std::string_view text = options_.comment;
        while (!text.empty()) {
            size_t nl = text.find('\n');
            h += "comment " + std::string(text.substr(0, nl)) + "\n";
            if (nl == std::string_view::npos) break;
            text.remove_prefix(nl + 1);
        }
        std::set<std::string> used;
        auto property = [&](ScalarType type, std::string name) {
            for (char& c : name)
                if (is_blank(c) || static_cast<unsigned char>(c) < 0x20) c = '_';
            if (name.empty()) name = "property";
            std::string unique = name;
            for (int k = 2; !used.insert(unique).second; ++k) unique = name + "_" + std::to_string(k);
            h += "property ";
            h += scalar_type_name(type);
            h += ' ';
            h += unique;
            h += '\n';
        };
        h += "element vertex " + std::to_string(vertices) + "\n";
        for (const char* name : {"x", "y", "z"}) property(ScalarType::kFloat32, name);
        if (ch.normal)
            for (const char* name : {"nx", "ny", "nz"}) property(ScalarType::kFloat32, name);
        if (ch.color) {
            static const char* const kNames[4] = {"red", "green", "blue", "alpha"};
            for (int a = 0; a < (ch.color->alpha ? 4 : 3); ++a) property(ch.color->type, kNames[a]);
        }
        for (int set = 0; set < ch.uv_sets; ++set)
            for (int c = 0; c < 2; ++c) property(ScalarType::kFloat32, uv_name(set, c));
        for (const ScalarChannel& s : ch.vertex_scalars) property(s.type, s.name);
        h += "element face " + std::to_string(welder_.triangle_count()) + "\n";
        h += "property list uchar int vertex_indices\n";
        used = {"vertex_indices"};
        for (const ScalarChannel& s : ch.face_scalars) property(s.type, s.name);
        h += "end_header\n";
        return h;
    }

    // A float field: shortest round-trip text after a space (none before the first), or 4 bytes.
    void put_field(std::string& out, float v, bool first = false) const {
        if (ascii_ && !first) out += ' ';
        put_value(out, v, ascii_);
    }
    void flush(std::string& out) {
        sink_.write(out);
        out.clear();
    }

    ByteSink& sink_;
    WriteOptions options_;
    bool ascii_;
    Welder welder_;
    std::unique_ptr<TempFile> faces_;  // face scalars, in input order (when there are any)
    std::vector<double> face_block_;
};

std::unique_ptr<Reader> open_ply_reader(ByteSource& source, const ReadOptions& options) {
    return std::make_unique<PlyReader>(source, options);
}

std::unique_ptr<Writer> open_ply_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<PlyWriter>(sink, options, false);
}

std::unique_ptr<Writer> open_ply_ascii_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<PlyWriter>(sink, options, true);
}

// PLY holds every per-corner and per-face channel as vertex and face properties. A material
// table (names, colours, textures) has no place in it, so materials are dropped (the commands
// say so).
Channels ply_keep_channels(const Channels& in, const WriteOptions&) {
    Channels out = in;
    out.material = false;
    return out;
}

}  // namespace

bool probe_ply(std::span<const std::byte> head, std::optional<uint64_t>) {
    auto starts = [&](std::string_view magic) {
        return head.size() >= magic.size() && std::memcmp(head.data(), magic.data(), magic.size()) == 0;
    };
    return starts("ply\n") || starts("ply\r\n");
}

const Format kPlyFormat = {
    "ply",
    "ply",
    "PLY, binary little endian (reads ascii, binary little and big endian)",
    &probe_ply,
    &open_ply_reader,
    &open_ply_writer,
    0,
    nullptr,
    &ply_keep_channels,
};

const Format kPlyAsciiFormat = {
    "ply-ascii",
    "",
    "PLY, ascii (written when named, having no extension of its own)",
    nullptr,
    &open_ply_reader,
    &open_ply_ascii_writer,
    0,
    nullptr,
    &ply_keep_channels,
};

}  // namespace meshstream::io
