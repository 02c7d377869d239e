// PLY reader and writer. The header is parsed line by line (CRLF and trailing blanks allowed);
// the body is decoded from the ByteSource's window with explicit byte-order helpers (binary) or
// whitespace-separated tokens parsed with std::from_chars (ascii), the way miniply walks its
// refill buffer. Based on Greg Turk's PLY description and the quirks seen in PDAL's PlyReader
// and happly: type aliases (float32, uint8, ...), `vertex_index` as well as `vertex_indices`,
// elements in any order around vertex and face. Without a face element, a `tristrips` element
// (old Stanford scans: one list of vertex indices per strip, -1 restarting) is read instead.
#include "io/ply.hpp"

#include "io/error.hpp"
#include "io/text_number.hpp"
#include "io/vertex_table.hpp"
#include "io/weld.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

namespace meshstream::io {
namespace {

constexpr std::string_view kSortMarker = "meshstream sorted-axis=";
constexpr size_t kMaxTokenBytes = 4096;

enum class PlyType : uint8_t { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

size_t type_size(PlyType t) {
    switch (t) {
        case PlyType::kInt8: case PlyType::kUint8: return 1;
        case PlyType::kInt16: case PlyType::kUint16: return 2;
        case PlyType::kInt32: case PlyType::kUint32: case PlyType::kFloat32: return 4;
        case PlyType::kFloat64: return 8;
    }
    return 0;
}

bool is_float_type(PlyType t) { return t == PlyType::kFloat32 || t == PlyType::kFloat64; }

std::optional<PlyType> type_from_name(std::string_view s) {
    if (s == "char" || s == "int8") return PlyType::kInt8;
    if (s == "uchar" || s == "uint8") return PlyType::kUint8;
    if (s == "short" || s == "int16") return PlyType::kInt16;
    if (s == "ushort" || s == "uint16") return PlyType::kUint16;
    if (s == "int" || s == "int32") return PlyType::kInt32;
    if (s == "uint" || s == "uint32") return PlyType::kUint32;
    if (s == "float" || s == "float32") return PlyType::kFloat32;
    if (s == "double" || s == "float64") return PlyType::kFloat64;
    return std::nullopt;
}

enum class Encoding { kAscii, kBinaryLittle, kBinaryBig };

struct Property {
    std::string name;
    PlyType type = PlyType::kFloat32;
    bool is_list = false;
    PlyType count_type = PlyType::kUint8;
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
            n += type_size(p.type);
        }
        return n;
    }
};

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

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

// How a colour property of type t travels: 8-bit and wider integers as value / 255 (PLY's
// convention for colour), 16-bit ones as value / 65535, floats as they are.
ColorFormat color_format(PlyType t, bool alpha) {
    if (is_float_type(t)) return {ScalarType::kFloat32, alpha};
    if (t == PlyType::kUint16 || t == PlyType::kInt16) return {ScalarType::kUInt16, alpha};
    return {ScalarType::kUInt8, alpha};
}

float to_color(double v, const ColorFormat& f) {
    if (f.type == ScalarType::kFloat32) return static_cast<float>(v);
    return static_cast<float>(v / (f.type == ScalarType::kUInt16 ? 65535.0 : 255.0));
}

// ---------------- reader ----------------

class PlyReader : public Reader {
public:
    PlyReader(ByteSource& source, const ReadOptions& options) : src_(source), options_(options) {
        parse_header();
        read_up_to_faces();
    }

    bool next(TriangleChunk& chunk) override {
        chunk.clear();
        for (;;) {
            if (polygon_next_ + 2 < polygon_.size()) {
                const CornerLayout* layout = layout_ ? &*layout_ : nullptr;
                if (!emit_polygon(*table_, layout, polygon_, polygon_scratch_, &polygon_next_, chunk)) return true;
            }
            if (chunk.full()) return true;
            if (strip_next_ < strip_triangles_.size()) {  // the current strip, a triangle at a time
                polygon_.assign(strip_triangles_.begin() + strip_next_, strip_triangles_.begin() + strip_next_ + 3);
                polygon_next_ = 0;
                strip_next_ += 3;
                continue;
            }
            // Elements after the faces carry nothing we use and are not read: real files get
            // them wrong (CGAL's colored_tetra.ply promises 3 properties per 'edge', writes 2).
            if (face_ < 0 || item_ == elements_[static_cast<size_t>(face_)].count) {
                if (chunk.empty()) reject_trailing_data();
                return !chunk.empty();
            }
            read_face();
        }
    }

private:
    // ---- header ----
    std::string header_line() {
        for (;;) {
            auto w = src_.window();
            const char* p = reinterpret_cast<const char*>(w.data());
            const void* nl = std::memchr(p, '\n', w.size());
            if (!nl && w.size() < ByteSource::kBufferBytes) {
                w = src_.peek(ByteSource::kBufferBytes);
                p = reinterpret_cast<const char*>(w.data());
                nl = std::memchr(p, '\n', w.size());
            }
            if (!nl) {
                if (w.size() >= ByteSource::kBufferBytes) header_fail("header line longer than 1 MiB");
                header_fail("file ends inside the header (no end_header line)");
            }
            size_t len = static_cast<size_t>(static_cast<const char*>(nl) - p);
            std::string line(p, len);
            src_.consume(len + 1);
            ++line_;
            while (!line.empty() && is_blank(line.back())) line.pop_back();
            return line;
        }
    }

    [[noreturn]] void header_fail(const std::string& message) const {
        throw Error(src_.name(), Error::kNoOffset, line_ + 1, message);
    }

    void parse_header() {
        std::string magic = header_line();
        if (magic != "ply") throw Error(src_.name(), 0, 0, "not a PLY file (first line is " + quote_token(magic) + ")");
        bool have_format = false;
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
                if (words[1] == "ascii") encoding_ = Encoding::kAscii;
                else if (words[1] == "binary_little_endian") encoding_ = Encoding::kBinaryLittle;
                else if (words[1] == "binary_big_endian") encoding_ = Encoding::kBinaryBig;
                else bad("unknown format " + quote_token(words[1]));
                header_.variant = std::string(words[1]);
                have_format = true;
            } else if (key == "element") {
                if (words.size() != 3) bad("expected 'element <name> <count>'");
                Element e;
                e.name = std::string(words[1]);
                auto [p, ec] = std::from_chars(words[2].data(), words[2].data() + words[2].size(), e.count);
                if (ec != std::errc() || p != words[2].data() + words[2].size()) bad("bad element count");
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
                bad("unknown keyword " + quote_token(key));
            }
        }
        if (!have_format) throw Error(src_.name(), Error::kNoOffset, line_, "PLY header has no 'format' line");
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
        if (vertex_ >= 0) {
            const Element& v = elements_[static_cast<size_t>(vertex_)];
            for (size_t p = 0; p < v.props.size(); ++p) {
                const std::string& n = v.props[p].name;
                int slot = n == "x"       ? 0
                           : n == "y"     ? 1
                           : n == "z"     ? 2
                           : n == "red"   ? 3
                           : n == "green" ? 4
                           : n == "blue"  ? 5
                           : n == "alpha" ? 6
                                          : -1;
                if (slot >= 0 && !v.props[p].is_list) vertex_props_[slot] = static_cast<int>(p);
            }
            for (int a = 0; a < 3; ++a)
                if (vertex_props_[a] < 0)
                    throw Error(src_.name(), Error::kNoOffset, line_,
                                std::string("vertex element has no property '") + char('x' + a) + "'");
            header_.vertex_count = v.count;
        }
        has_color_ = vertex_props_[3] >= 0 && vertex_props_[4] >= 0 && vertex_props_[5] >= 0;
        header_.channels.vertex_id = true;
        if (has_color_) {
            const Element& v = elements_[static_cast<size_t>(vertex_)];
            header_.channels.color =
                color_format(v.props[static_cast<size_t>(vertex_props_[3])].type, vertex_props_[6] >= 0);
        }
        uint64_t faces = face_ >= 0 ? elements_[static_cast<size_t>(face_)].count : 0;
        if (faces == 0) header_.triangle_count = 0;
        if (!strips_) header_.triangle_estimate = faces;
        header_.notes.emplace_back(strips_ ? "tristrips" : "faces", std::to_string(faces));
    }

    // ---- body primitives ----
    [[noreturn]] void item_fail(uint64_t offset, const std::string& message) const {
        const Element& e = elements_[element_];
        throw Error(src_.name(), offset, encoding_ == Encoding::kAscii ? line_ + 1 : 0,
                    "element '" + e.name + "' item " + std::to_string(item_) + ": " + message);
    }

    [[noreturn]] void truncated() const {
        const Element& e = elements_[element_];
        item_fail(src_.offset(), "file ends early (header promises " + std::to_string(e.count) + " " + e.name +
                                     " items)");
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
        if (swap_) {
            if constexpr (sizeof(U) == 2) v = std::bit_cast<U>(__builtin_bswap16(std::bit_cast<uint16_t>(v)));
            if constexpr (sizeof(U) == 4) v = std::bit_cast<U>(__builtin_bswap32(std::bit_cast<uint32_t>(v)));
            if constexpr (sizeof(U) == 8) v = std::bit_cast<U>(__builtin_bswap64(std::bit_cast<uint64_t>(v)));
        }
        return v;
    }

    double decode(const std::byte* p, PlyType t) const {
        switch (t) {
            case PlyType::kInt8: return load<int8_t>(p);
            case PlyType::kUint8: return load<uint8_t>(p);
            case PlyType::kInt16: return load<int16_t>(p);
            case PlyType::kUint16: return load<uint16_t>(p);
            case PlyType::kInt32: return load<int32_t>(p);
            case PlyType::kUint32: return load<uint32_t>(p);
            case PlyType::kFloat32: return load<float>(p);
            case PlyType::kFloat64: return load<double>(p);
        }
        return 0;
    }

    int64_t decode_int(const std::byte* p, PlyType t) const {
        switch (t) {
            case PlyType::kInt8: return load<int8_t>(p);
            case PlyType::kUint8: return load<uint8_t>(p);
            case PlyType::kInt16: return load<int16_t>(p);
            case PlyType::kUint16: return load<uint16_t>(p);
            case PlyType::kInt32: return load<int32_t>(p);
            case PlyType::kUint32: return load<uint32_t>(p);
            case PlyType::kFloat32: return static_cast<int64_t>(load<float>(p));
            case PlyType::kFloat64: return static_cast<int64_t>(load<double>(p));
        }
        return 0;
    }

    // Next whitespace-separated ascii token (its offset in token_offset_).
    std::string_view token() {
        for (;;) {
            auto w = src_.window();
            if (w.empty()) truncated();
            const char* p = reinterpret_cast<const char*>(w.data());
            size_t i = 0;
            while (i < w.size() && is_blank(p[i])) {
                if (p[i] == '\n') ++line_;
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
        src_.consume(j);
        return {p, j};
    }

    double parse_number(std::string_view tok) const {
        const char* b = tok.data();
        const char* e = b + tok.size();
        if (b != e && *b == '+') ++b;
        double v = 0;
        auto [p, ec] = std::from_chars(b, e, v);
        if (ec == std::errc::result_out_of_range) {
            // Subnormal or huge: keep strtod's value (from_chars leaves v unchanged here).
            v = std::strtod(std::string(tok).c_str(), nullptr);
        } else if (ec != std::errc() || p != e) {
            item_fail(token_offset_, "expected a number, found " + quote_token(tok));
        }
        return v;
    }

    float parse_float(std::string_view tok) const {
        const char* b = tok.data();
        const char* e = b + tok.size();
        if (b != e && *b == '+') ++b;
        float v = 0;
        auto [p, ec] = std::from_chars(b, e, v);
        if (ec == std::errc::result_out_of_range) v = std::strtof(std::string(tok).c_str(), nullptr);
        else if (ec != std::errc() || p != e) item_fail(token_offset_, "expected a number, found " + quote_token(tok));
        return v;
    }

    int64_t parse_integer(std::string_view tok) const {
        const char* b = tok.data();
        const char* e = b + tok.size();
        if (b != e && *b == '+') ++b;
        int64_t v = 0;
        auto [p, ec] = std::from_chars(b, e, v);
        if (ec == std::errc() && p == e) return v;
        double d = parse_number(tok);
        if (d != std::floor(d) || !(std::fabs(d) < 9e18)) item_fail(token_offset_, "expected an integer, found " + quote_token(tok));
        return static_cast<int64_t>(d);
    }

    double read_scalar(PlyType t) {
        if (encoding_ == Encoding::kAscii) return parse_number(token());
        size_t n = type_size(t);
        double v = decode(need(n), t);
        src_.consume(n);
        return v;
    }

    int64_t read_integer(PlyType t) {
        if (encoding_ == Encoding::kAscii) return parse_integer(token());
        size_t n = type_size(t);
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
            for (int64_t i = 0; i < n; ++i) parse_number(token());
        } else {
            uint64_t bytes = uint64_t(n) * type_size(p.type);
            if (src_.skip(bytes) != bytes) truncated();
        }
    }

    // A count whose byte size overflows 64 bits cannot be in any file.
    void check_size(const Element& e, size_t fixed) const {
        if (e.count > ~uint64_t{0} / fixed)
            throw Error(src_.name(), src_.offset(), 0,
                        "element '" + e.name + "': header promises " + std::to_string(e.count) + " items, more than any file holds");
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
            return;
        }
        for (item_ = 0; item_ < e.count; ++item_)
            for (const Property& p : e.props) skip_property(p);
    }

    // ---- vertices ----
    // Reads (or skips) the elements before the faces; the faces then stream from next().
    void read_up_to_faces() {
        for (size_t i = 0; i < elements_.size(); ++i) {
            element_ = i;
            item_ = 0;
            if (static_cast<int>(i) == face_) return;
            if (static_cast<int>(i) == vertex_) {
                read_vertices(i);
                if (face_ < 0) return;  // a point cloud: nothing more to read
            } else {
                skip_element(i);
            }
        }
    }

    void read_vertices(size_t index) {
        element_ = index;
        const Element& e = elements_[index];
        size_t fixed = e.fixed_bytes();
        const uint64_t budget = options_.memory_budget_bytes;
        // A plain file in host byte order with float x, y, z and no attributes is read in place.
        const CornerLayout layout(header_.channels);
        bool direct = encoding_ != Encoding::kAscii && !swap_ && fixed > 0 && !src_.regular_file_path().empty() &&
                      layout.bytes() == 0;
        size_t offsets[kSlots] = {};
        for (int s = 0; s < kSlots; ++s) {
            if (vertex_props_[s] < 0) continue;
            for (int p = 0; p < vertex_props_[s]; ++p) offsets[s] += type_size(e.props[static_cast<size_t>(p)].type);
            PlyType t = e.props[static_cast<size_t>(vertex_props_[s])].type;
            if (s < 3 && t != PlyType::kFloat32) direct = false;
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
            const size_t xyz[3] = {offsets[0], offsets[1], offsets[2]};
            table_ = VertexTable::of_input_file(src_.regular_file_path(), start, e.count, fixed, xyz, budget);
            header_.notes.emplace_back("vertex table", "input file, read in place");
            return;
        }
        table_ = std::make_unique<VertexTable>(budget, options_.tmpdir, layout.bytes());
        layout_ = layout;
        // meshstream's chunks hold float coordinates: double ones are rounded, which far from
        // the origin moves them by a lot (0.25 m at 4 000 000); the largest change is said.
        bool doubles = false;
        for (int s = 0; s < 3; ++s)
            doubles |= e.props[static_cast<size_t>(vertex_props_[s])].type == PlyType::kFloat64;
        double worst_rounding = 0, worst_at = 0;
        double values[kSlots] = {0, 0, 0, 0, 0, 0, 1};
        float xyz[3];
        float rgba[4] = {0, 0, 0, 1};
        std::vector<std::byte> record(layout.bytes());
        for (item_ = 0; item_ < e.count; ++item_) {
            if (fixed > 0 && encoding_ != Encoding::kAscii) {
                const std::byte* rec = need(fixed);
                for (int s = 0; s < kSlots; ++s)
                    if (vertex_props_[s] >= 0)
                        values[s] = decode(rec + offsets[s], e.props[static_cast<size_t>(vertex_props_[s])].type);
                src_.consume(fixed);
            } else {
                for (size_t p = 0; p < e.props.size(); ++p) {
                    const Property& prop = e.props[p];
                    int slot = -1;
                    for (int s = 0; s < kSlots; ++s)
                        if (vertex_props_[s] == static_cast<int>(p)) slot = s;
                    if (slot >= 0 && slot < 3 && encoding_ == Encoding::kAscii && prop.type != PlyType::kFloat64)
                        values[slot] = parse_float(token());  // decimal -> float directly: no double rounding
                    else if (slot >= 0)
                        values[slot] = read_scalar(prop.type);
                    else skip_property(prop);
                }
            }
            for (int a = 0; a < 3; ++a) xyz[a] = static_cast<float>(values[a]);
            if (doubles)
                for (int a = 0; a < 3; ++a)
                    if (std::fabs(double(xyz[a]) - values[a]) > worst_rounding) {
                        worst_rounding = std::fabs(double(xyz[a]) - values[a]);
                        worst_at = values[a];
                    }
            if (has_color_) {
                for (int a = 0; a < 4; ++a)
                    if (a < 3 || vertex_props_[6] >= 0) rgba[a] = to_color(values[3 + a], *header_.channels.color);
                layout.pack_values(nullptr, rgba, nullptr, nullptr, record.data());
            }
            table_->append(xyz, record.data());
        }
        header_.notes.emplace_back("vertex table", table_->storage() == VertexTable::Storage::kMemory
                                                       ? "in memory"
                                                       : "temporary file");
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
        polygon_.clear();
        polygon_next_ = 0;
        for (size_t p = 0; p < e.props.size(); ++p) {
            const Property& prop = e.props[p];
            if (static_cast<int>(p) != index_prop_) {
                skip_property(prop);
                continue;
            }
            int64_t n = read_count(prop);
            const uint64_t vertices = table_->size();
            for (int64_t k = 0; k < n; ++k) {
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
            else if (n < 3 && options_.strict)
                item_fail(token_offset_, "face with " + std::to_string(n) + " vertices (--strict)");
        }
        ++item_;
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

    // When the faces are the last element, anything but blanks after them is data the header
    // does not count: its face count is short (issue 7; it used to be ignored silently).
    // In ASCII, no line end after the last face is noted: a cut inside its last index ("3 9 10 1"
    // of "3 9 10 11") is otherwise a valid file.
    void reject_trailing_data() {
        if (face_ < 0 || static_cast<size_t>(face_) + 1 != elements_.size() || trailing_checked_) return;
        trailing_checked_ = true;
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
                    item_fail(src_.offset(), "data after the last of the " + std::to_string(item_) +
                                                 " faces the header promises");
                }
            }
            src_.consume(w.size());
        }
    }

    ByteSource& src_;
    ReadOptions options_;
    Encoding encoding_ = Encoding::kAscii;
    bool swap_ = false;
    uint64_t line_ = 0;  // lines consumed (header; ascii body)
    bool trailing_checked_ = false;
    std::vector<Element> elements_;
    int vertex_ = -1, face_ = -1, index_prop_ = -1;
    static constexpr int kSlots = 7;
    int vertex_props_[kSlots] = {-1, -1, -1, -1, -1, -1, -1};  // x y z red green blue alpha
    std::optional<CornerLayout> layout_;  // the vertex table's corner records, when it has them
    bool has_color_ = false;
    size_t element_ = 0;  // element being read (for messages)
    uint64_t item_ = 0;   // item number within it
    uint64_t token_offset_ = 0;
    std::unique_ptr<VertexTable> table_;
    std::vector<uint64_t> polygon_;
    PolygonScratch polygon_scratch_;
    size_t polygon_next_ = 0;  // next triangle of polygon_ to emit
    bool strips_ = false;      // face_ is a tristrips element
    std::vector<uint64_t> strip_triangles_;  // index triples of the strips read, emitted from strip_next_
    size_t strip_next_ = 0;
};

// ---------------- writer ----------------

class PlyWriter : public Writer {
public:
    PlyWriter(ByteSink& sink, const WriteOptions& options, bool ascii)
        : sink_(sink), options_(options), ascii_(ascii),
          welder_(options.memory_budget_bytes, options.tmpdir, sink.name(), options.channels) {}

    void write_chunk(const TriangleChunk& chunk) override { welder_.add(chunk); }

    void finish_output() override {
        welder_.finish();
        const uint64_t vertices = welder_.vertex_count();
        if (vertices > 0x7fffffffULL)
            throw Error(sink_.name(), "PLY int indices hold at most 2^31 - 1 vertices, the mesh has " +
                                          std::to_string(vertices));
        const std::optional<ColorFormat> color = options_.channels.color;
        const char* color_type = !color                                  ? ""
                                 : color->type == ScalarType::kUInt8 ? "uchar"
                                 : color->type == ScalarType::kUInt16 ? "ushort"
                                                                      : "float";
        const int color_n = color ? (color->alpha ? 4 : 3) : 0;
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
        h += "element vertex " + std::to_string(vertices) + "\n";
        h += "property float x\nproperty float y\nproperty float z\n";
        for (int a = 0; a < color_n; ++a) {
            static const char* const kNames[4] = {"red", "green", "blue", "alpha"};
            h += "property " + std::string(color_type) + " " + kNames[a] + "\n";
        }
        h += "element face " + std::to_string(welder_.triangle_count()) + "\n";
        h += "property list uchar int vertex_indices\nend_header\n";
        sink_.write(h);

        const CornerLayout& layout = welder_.layout();
        std::vector<float> xyz(3 * 8192);
        std::vector<std::byte> records(layout.bytes() * 8192);
        std::string out;
        out.reserve(size_t{1} << 20);
        while (size_t n = welder_.next_vertices(xyz, records)) {
            for (size_t i = 0; i < n; ++i) {
                const float* p = &xyz[3 * i];
                float rgba[4] = {0, 0, 0, 1};
                if (color) layout.unpack_values(&records[layout.bytes() * i], nullptr, rgba, nullptr, nullptr);
                if (ascii_) {
                    for (int a = 0; a < 3; ++a) {
                        if (a) out += ' ';
                        append_number(out, p[a]);
                    }
                    for (int a = 0; a < color_n; ++a) {
                        out += ' ';
                        if (color->type == ScalarType::kFloat32)
                            append_number(out, rgba[a]);
                        else
                            append_number(out, unsigned(std::lround(std::clamp(rgba[a], 0.0f, 1.0f) *
                                                                    (color->type == ScalarType::kUInt8 ? 255.0f : 65535.0f))));
                    }
                    out += '\n';
                } else {
                    char buf[12 + 16];
                    for (int a = 0; a < 3; ++a) store_le(buf + 4 * a, std::bit_cast<uint32_t>(p[a]));
                    size_t at = 12;
                    for (int a = 0; a < color_n; ++a) {
                        const float c = std::clamp(rgba[a], 0.0f, 1.0f);
                        if (color->type == ScalarType::kUInt8) {
                            buf[at++] = static_cast<char>(std::lround(c * 255.0f));
                        } else if (color->type == ScalarType::kUInt16) {
                            const auto v = static_cast<uint16_t>(std::lround(c * 65535.0f));
                            buf[at++] = static_cast<char>(v & 0xff);
                            buf[at++] = static_cast<char>(v >> 8);
                        } else {
                            store_le(buf + at, std::bit_cast<uint32_t>(rgba[a]));
                            at += 4;
                        }
                    }
                    out.append(buf, at);
                }
            }
            flush(out);
        }
        std::vector<uint32_t> idx(3 * 8192);
        while (size_t n = welder_.next_indices(idx)) {
            for (size_t t = 0; t + 2 < n; t += 3) {
                if (ascii_) {
                    out += '3';
                    for (int k = 0; k < 3; ++k) {
                        out += ' ';
                        append_number(out, idx[t + k]);
                    }
                    out += '\n';
                } else {
                    char buf[13];
                    buf[0] = 3;
                    for (int k = 0; k < 3; ++k) store_le(buf + 1 + 4 * k, idx[t + k]);
                    out.append(buf, 13);
                }
            }
            flush(out);
        }
        flush(out);
    }

private:
    static void store_le(char* p, uint32_t v) {
        for (int i = 0; i < 4; ++i) p[i] = static_cast<char>((v >> (8 * i)) & 0xff);
    }
    void flush(std::string& out) {
        sink_.write(out);
        out.clear();
    }

    ByteSink& sink_;
    WriteOptions options_;
    bool ascii_;
    Welder welder_;
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

// PLY holds every channel as vertex and face properties; this writer writes colour so far.
Channels ply_keep_channels(const Channels& in, const WriteOptions&) {
    Channels out;
    out.color = in.color;
    out.vertex_id = in.vertex_id;
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
    "PLY, ascii (write with --to ply-ascii)",
    nullptr,
    &open_ply_reader,
    &open_ply_ascii_writer,
    0,
    nullptr,
    &ply_keep_channels,
};

}  // namespace meshstream::io
