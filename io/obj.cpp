// OBJ reader and writer: line-based parsing from the ByteSource window (lines up to 1 MiB,
// `\` continuations joined in a scratch string), words and numbers in the text grammar of
// io/text_tokens.hpp (std::from_chars), as fast_obj does with its 64 KiB refill loop;
// positions, texture coordinates and normals in three spillable tables sharing the budget; the
// writer spools through io::Welder and writes its .mtl and texture images beside the output as
// the .gltf writer does its .bin.
#include "io/obj.hpp"

#include "io/error.hpp"
#include "io/hash.hpp"
#include "io/line_reader.hpp"
#include "io/mtl.hpp"
#include "io/text_number.hpp"
#include "io/text_tokens.hpp"
#include "io/triangulate.hpp"
#include "io/vertex_table.hpp"
#include "io/weld.hpp"

#include <sys/stat.h>
#include <algorithm>
#include <cassert>
#include <charconv>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

namespace meshstream::io {
namespace {

constexpr std::string_view kSortMarker = "meshstream sorted-axis=";
constexpr uint64_t kNone = ~uint64_t{0};  // a corner without vt or vn
constexpr uint32_t kNoMaterial = ~uint32_t{0};
constexpr const char* kDefaultMaterial = "default";
// The header note key of what the reader skipped or filled in (one sentence each).
constexpr const char* kObjWarningNote = "warning";
// The counted warning (MeshHeader::warnings) of a usemtl without a name.
constexpr const char* kNamelessUsemtlWarning =
    "usemtl statements without a material name read as material 'default', that of faces before any usemtl";

bool file_exists(const std::string& path) {
    struct stat st;
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string base_name(const std::string& path) {
    size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string plural(uint64_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

std::string joined(const std::vector<std::string>& items, size_t max_items = 5) {
    std::string out;
    for (size_t i = 0; i < items.size() && i < max_items; ++i) out += (i ? ", " : "") + items[i];
    if (items.size() > max_items) out += " and " + std::to_string(items.size() - max_items) + " more";
    return out;
}

// Statements that carry no geometry meshstream keeps and need no word: grouping, smoothing,
// display and rendering attributes.
bool is_quiet_statement(std::string_view key) {
    static constexpr std::string_view kQuiet[] = {"g",        "o",        "s",          "mg",        "lod",    "bevel",
                                                  "c_interp", "d_interp", "shadow_obj", "trace_obj", "maplib", "usemap",
                                                  "ctech",    "stech",    "call",       "csh"};
    return std::find(std::begin(kQuiet), std::end(kQuiet), key) != std::end(kQuiet);
}

// Free-form geometry (curves and surfaces) and its parameters: skipped, counted.
bool is_free_form_statement(std::string_view key) {
    static constexpr std::string_view kFreeForm[] = {"vp",   "cstype", "deg",  "bmat", "step", "curv", "curv2", "surf",
                                                     "parm", "trim",   "hole", "scrv", "sp",   "end",  "con"};
    return std::find(std::begin(kFreeForm), std::end(kFreeForm), key) != std::end(kFreeForm);
}

// Vertex ids for corners with texture coordinates or normals: one id per distinct (v, vt, vn)
// triple, so corners of one position with different attributes (seams) are different vertices.
// A 4-way set-associative table of 40-byte entries. It doubles whenever a set it must add to
// is full (or it is half full), as long as the doubled table fits its budget, so within the
// budget it forgets nothing; at its largest, a full set gives up its least recently used
// entry. Ids are handed out in order of first use and never reused, so two different triples
// never share one; a triple forgotten and met again gets a second id (its vertex is then
// written twice, with the same values).
class CornerIds {
public:
    explicit CornerIds(uint64_t budget_bytes) : budget_(budget_bytes) { rebuild(kMinSets); }

    void set_budget(uint64_t budget_bytes) {
        budget_ = budget_bytes;
        size_t sets = sets_;
        while (sets > kMinSets && bytes(sets) > budget_) sets /= 2;
        if (sets != sets_) rebuild(sets);
    }

    uint64_t id(uint64_t v, uint64_t vt, uint64_t vn) {
        ++clock_;
        Entry* set = set_of(v, vt, vn);
        for (size_t w = 0; w < kWays; ++w)
            if (set[w].stamp != 0 && set[w].v == v && set[w].vt == vt && set[w].vn == vn) {
                set[w].stamp = clock_;
                return set[w].id;
            }
        while ((full(set) || (used_ + 1) * 2 > sets_ * kWays) && bytes(2 * sets_) <= budget_) {
            rebuild(2 * sets_);
            set = set_of(v, vt, vn);
        }
        const uint64_t id = next_id_++;
        place(set, Entry{v, vt, vn, id, clock_});
        return id;
    }

    uint64_t forgotten() const { return forgotten_; }

private:
    struct Entry {
        uint64_t v, vt, vn, id;
        uint64_t stamp;  // last use; 0: empty
    };
    static constexpr size_t kWays = 4;
    static constexpr size_t kMinSets = 1024;  // 160 KiB

    static uint64_t bytes(size_t sets) { return uint64_t{sets} * kWays * sizeof(Entry); }
    static uint64_t hash(uint64_t v, uint64_t vt, uint64_t vn) {
        return mix64(v ^ mix64(vt + 0x9e3779b97f4a7c15ULL) ^ mix64(vn * 0xc2b2ae3d27d4eb4fULL + 1));
    }
    Entry* set_of(uint64_t v, uint64_t vt, uint64_t vn) { return &table_[(hash(v, vt, vn) & (sets_ - 1)) * kWays]; }
    static bool full(const Entry* set) {
        return std::all_of(set, set + kWays, [](const Entry& e) { return e.stamp != 0; });
    }

    void place(Entry* set, const Entry& e) {
        Entry* victim = &set[0];
        for (size_t w = 0; w < kWays; ++w) {
            if (set[w].stamp == 0) {
                victim = &set[w];
                break;
            }
            if (set[w].stamp < victim->stamp) victim = &set[w];
        }
        if (victim->stamp != 0)
            ++forgotten_;
        else
            ++used_;
        *victim = e;
    }

    // Re-files every entry into `sets` sets (more when one of them overflows and the budget
    // allows), the older first so that the newer win a full set.
    void rebuild(size_t sets) {
        std::vector<Entry> old;
        old.swap(table_);
        std::erase_if(old, [](const Entry& e) { return e.stamp == 0; });
        std::sort(old.begin(), old.end(), [](const Entry& a, const Entry& b) { return a.stamp < b.stamp; });
        for (;; sets *= 2) {
            sets_ = sets;
            used_ = 0;
            table_.assign(sets_ * kWays, Entry{0, 0, 0, 0, 0});
            bool overflow = false;
            for (const Entry& e : old) {
                Entry* set = set_of(e.v, e.vt, e.vn);
                if (full(set) && bytes(2 * sets_) <= budget_) {
                    overflow = true;
                    break;
                }
                place(set, e);
            }
            if (!overflow) return;
        }
    }

    uint64_t budget_;
    std::vector<Entry> table_;
    size_t sets_ = 0, used_ = 0;
    uint64_t clock_ = 0, next_id_ = 0, forgotten_ = 0;
};

struct Corner {
    uint64_t v, vt, vn;  // 0-based; vt, vn kNone when absent
};

class ObjReader : public Reader {
public:
    ObjReader(ByteSource& source, const ReadOptions& options)
        : src_(source),
          options_(options),
          dir_(source.name() == "<stdin>" ? "." : parent_dir(source.name())),
          image_budget_(options.memory_budget_bytes) {
        header_.channels.vertex_id = true;
        auto bom = src_.peek(3);  // a UTF-8 byte order mark would hide the first statement
        if (bom.size() == 3 && std::memcmp(bom.data(), "\xEF\xBB\xBF", 3) == 0) src_.consume(3);
        // Everything up to the first face is read now: the stream's channels follow what it
        // uses (see obj.hpp), and a "# meshstream sorted-axis=" comment is in the header.
        face_pending_ = next_statement();
        if (!decided_) decide(nullptr);
        publish_notes();
    }

    bool next(TriangleChunk& chunk) override {
        chunk.clear();
        for (;;) {
            if (face_pending_) {
                if (!emit_face(chunk)) return true;  // the chunk is full; the face goes on
                face_pending_ = false;
            }
            if (chunk.full()) return true;
            if (!next_statement()) {
                if (!published_at_end_) {
                    published_at_end_ = true;
                    publish_notes();
                }
                return !chunk.empty();
            }
            face_pending_ = true;
        }
    }

private:
    [[noreturn]] void fail(const std::string& message) const {
        throw Error(src_.name(), line_offset_, line_no_, message);
    }

    // Reads the next logical line into line_; false at the end of the input.
    bool next_line() {
        if (!lines_.next(line_)) {
            if (lines_.unterminated() && !noted_unterminated_) {
                header_.notes.emplace_back(kLastLineNote, kLastLineText);
                noted_unterminated_ = true;
            }
            return false;
        }
        line_offset_ = lines_.line_offset();
        line_no_ = lines_.line_number();
        return true;
    }

    // Handles statements up to the next face of three corners or more, which it leaves in
    // face_. False at the end of the input.
    bool next_statement() {
        for (;;) {
            if (!next_line()) return false;
            std::string_view rest = line_;
            std::string_view key = next_word(rest);
            if (key.empty()) continue;
            if (key[0] == '#') {
                note_comment();
                continue;
            }
            // A comment may end a statement's line ("f 1 2 3 # top"), as most readers allow.
            // (Not for names: mtllib and usemtl take the rest of the line.)
            if (key == "v" || key == "vt" || key == "vn" || key == "f" || key == "fo")
                rest = rest.substr(0, rest.find('#'));
            if (key == "v") {
                read_position(rest);
            } else if (key == "vt") {
                read_texture_coordinate(rest);
            } else if (key == "vn") {
                read_normal(rest);
            } else if (key == "f" || key == "fo") {  // "fo": the face keyword of old OBJ files
                if (read_face(rest)) return true;
            } else if (key == "usemtl") {
                use_material(trim_blanks(rest));
            } else if (key == "mtllib") {
                load_material_libraries(trim_blanks(rest));
            } else if (key == "l" || key == "p") {
                ++lines_and_points_;
            } else if (is_free_form_statement(key)) {
                ++free_form_;
            } else if (!is_quiet_statement(key)) {
                // Statement names are ASCII words ("c_interp", "curv2"); anything else is not
                // OBJ text (random bytes under .obj used to read as zero triangles).
                if (!std::all_of(key.begin(), key.end(), [](char c) {
                        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
                    }))
                    fail("not an OBJ statement: " + quote_token(key));
                if (unknown_++ == 0) first_unknown_ = "'" + std::string(key) + "' at line " + std::to_string(line_no_);
            }
        }
    }

    void note_comment() {
        size_t at = line_.find(kSortMarker);
        if (at != std::string_view::npos && at + kSortMarker.size() < line_.size()) {
            char axis = line_[at + kSortMarker.size()];
            if (axis >= 'x' && axis <= 'z') header_.sorted_axis = axis - 'x';
        }
    }

    float parse_number(std::string_view tok, const char* what) const {
        float v = 0;
        if (!io::parse_number(tok, v)) fail(std::string("expected ") + what + ", found " + quote_token(tok));
        return v;
    }

    // The budget is shared among the tables: positions weigh 2 (their table is the largest
    // and the most read), texture coordinates, normals and corner ids 1 each.
    void share_budget() {
        const uint64_t weights = (positions_ ? 2 : 0) + (uvs_ ? 1 : 0) + (normals_ ? 1 : 0) + (ids_ ? 1 : 0);
        if (weights == 0) return;
        const uint64_t unit = options_.memory_budget_bytes / weights;
        if (positions_) positions_->set_budget(2 * unit);
        if (uvs_) uvs_->set_budget(unit);
        if (normals_) normals_->set_budget(unit);
        if (ids_) ids_->set_budget(unit);
    }

    void read_position(std::string_view rest) {
        float xyz[3];
        for (int a = 0; a < 3; ++a) {
            std::string_view tok = next_word(rest);
            if (tok.empty()) fail("'v' needs 3 coordinates, found " + std::to_string(a));
            xyz[a] = parse_number(tok, "a coordinate");
        }
        // What may follow x y z: w, colour (r g b), or both (w r g b); numbers only, so that a
        // lost line end ("v 0 0 0 v 1 0 0") is an error instead of a dropped vertex.
        float extra[4];
        int n = 0;
        for (std::string_view tok = next_word(rest); !tok.empty(); tok = next_word(rest), ++n) {
            const float v = parse_number(tok, "a number (w or colour) after 'v x y z'");
            if (n < 4) extra[n] = v;
        }
        if (n == 2 || n > 4) fail("'v' with " + std::to_string(3 + n) + " numbers (x y z, then w and/or r g b)");
        const bool has_color = n >= 3;
        if (!positions_) {  // the first vertex decides whether vertices carry a colour
            color_ = has_color;
            if (color_) header_.channels.color = ColorFormat{ScalarType::kFloat32, false};
            positions_ = std::make_unique<VertexTable>(options_.memory_budget_bytes, options_.tmpdir,
                                                       color_ ? 3 * sizeof(float) : 0);
            share_budget();
        }
        float rgb[3] = {1.0f, 1.0f, 1.0f};                          // white for a vertex without colour
        if (has_color) std::copy(extra + (n - 3), extra + n, rgb);  // r g b are the last three
        if (color_ && !has_color) ++vertices_without_color_;
        if (!color_ && has_color) ++colors_dropped_;
        positions_->append(xyz, reinterpret_cast<const std::byte*>(rgb));
    }

    void read_texture_coordinate(std::string_view rest) {
        float uvw[3] = {0.0f, 0.0f, 0.0f};  // v and w default to 0
        int n = 0;
        for (std::string_view tok = next_word(rest); !tok.empty(); tok = next_word(rest), ++n) {
            if (n == 3) fail("'vt' with more than 3 numbers (u v w)");
            uvw[n] = parse_number(tok, "a texture coordinate");
        }
        if (n == 0) fail("'vt' needs a texture coordinate (u, v), found none");
        ++uv_count_;
        if (decided_ && !uv_) return;  // counted for index checks only: not kept
        if (!uvs_) {
            uvs_ = std::make_unique<VertexTable>(options_.memory_budget_bytes, options_.tmpdir, 0);
            share_budget();
        }
        uvw[2] = 0.0f;  // the record's third float is unused: w is not kept
        uvs_->append(uvw, nullptr);
    }

    void read_normal(std::string_view rest) {
        float n[3];
        int count = 0;
        for (std::string_view tok = next_word(rest); !tok.empty(); tok = next_word(rest), ++count) {
            if (count == 3) fail("'vn' with more than 3 numbers");
            n[count] = parse_number(tok, "a normal component");
        }
        if (count != 3) fail("'vn' needs 3 numbers, found " + std::to_string(count));
        ++normal_count_;
        if (decided_ && !normal_) return;
        if (!normals_) {
            normals_ = std::make_unique<VertexTable>(options_.memory_budget_bytes, options_.tmpdir, 0);
            share_budget();
        }
        normals_->append(n, nullptr);
    }

    // One index of a corner ("-3", "12"), 0-based, checked against the `defined` elements.
    uint64_t parse_index(std::string_view num, std::string_view tok, uint64_t defined, const char* what,
                         const char* elements) const {
        const char* b = num.data();
        const char* e = b + num.size();
        // Most indices are plain positive numbers: read in line (std::from_chars is a call).
        if (b != e && e - b <= 18 && *b >= '1' && *b <= '9') {
            uint64_t v = 0;
            const char* q = b;
            for (; q != e && static_cast<unsigned>(*q - '0') < 10; ++q) v = v * 10 + static_cast<unsigned>(*q - '0');
            if (q == e && v <= defined) return v - 1;
        }
        int64_t index = 0;
        if (!parse_integer(num, index)) fail(std::string("expected a ") + what + " index, found " + quote_token(tok));
        if (index == 0) fail(std::string(what) + " index 0 is invalid (OBJ indices start at 1)");
        int64_t zero_based = index > 0 ? index - 1 : static_cast<int64_t>(defined) + index;
        if (zero_based < 0 || static_cast<uint64_t>(zero_based) >= defined)
            fail(std::string(what) + " index " + std::to_string(index) + " refers past the " + std::to_string(defined) +
                 " " + elements + " defined so far");
        return static_cast<uint64_t>(zero_based);
    }

    // Reads a face into face_; false when it has fewer than three corners (skipped, counted).
    bool read_face(std::string_view rest) {
        face_.clear();
        const uint64_t positions = positions_ ? positions_->size() : 0;
        for (std::string_view tok = next_word(rest); !tok.empty(); tok = next_word(rest)) {
            // "v", "v/vt", "v//vn", "v/vt/vn".
            const size_t slash = tok.find('/');
            Corner c{parse_index(tok.substr(0, slash), tok, positions, "vertex", "vertices"), kNone, kNone};
            if (slash != std::string_view::npos) {
                std::string_view rest_of = tok.substr(slash + 1);
                const size_t second = rest_of.find('/');
                const std::string_view vt = rest_of.substr(0, second);
                if (!vt.empty())
                    c.vt = parse_index(vt, tok, uv_count_, "texture coordinate", "texture coordinates (vt)");
                if (second != std::string_view::npos) {
                    const std::string_view vn = rest_of.substr(second + 1);
                    if (vn.find('/') != std::string_view::npos)
                        fail("expected v, v/vt, v//vn or v/vt/vn, found " + quote_token(tok));
                    if (!vn.empty()) c.vn = parse_index(vn, tok, normal_count_, "normal", "normals (vn)");
                }
            }
            face_.push_back(c);
        }
        if (face_.size() < 3) {
            if (options_.strict) fail("face with " + std::to_string(face_.size()) + " vertices (" + mention(Setting::kStrict) + ")");
            ++short_faces_;
            return false;
        }
        if (!decided_) decide(&face_);
        bool uv_dropped = false, normal_dropped = false;
        for (const Corner& c : face_) {
            if (uv_ && c.vt == kNone) ++corners_without_uv_;
            if (!uv_ && c.vt != kNone) uv_dropped = true;
            if (normal_ && c.vn == kNone) ++corners_without_normal_;
            if (!normal_ && c.vn != kNone) normal_dropped = true;
        }
        uv_faces_dropped_ += uv_dropped;
        normal_faces_dropped_ += normal_dropped;
        face_material_ = current_material_;
        polygon_next_ = 0;
        face_loaded_ = false;
        return true;
    }

    // The first face (null: the input has none) decides the channels: texture coordinates and
    // normals when it uses them, materials when mtllib or usemtl came before it.
    void decide(const std::vector<Corner>* first_face) {
        decided_ = true;
        if (first_face)
            for (const Corner& c : *first_face) {
                uv_ = uv_ || c.vt != kNone;
                normal_ = normal_ || c.vn != kNone;
            }
        header_.channels.uv_sets = uv_ ? 1 : 0;
        header_.channels.normal = normal_;
        material_ = saw_material_statement_;
        header_.channels.material = material_;
        if (!uv_) uvs_.reset();
        if (!normal_) normals_.reset();
        share_budget();
        // Faces before the first usemtl (a file that names its library first) need a material.
        if (material_ && first_face && current_material_ == kNoMaterial)
            current_material_ = material_index(kDefaultMaterial);
    }

    uint32_t material_index(std::string_view name) {
        auto it = material_ids_.find(std::string(name));
        if (it != material_ids_.end()) return it->second;
        if (header_.materials.size() >= kNoMaterial) fail("more than 2^32 - 1 materials");
        const uint32_t index = static_cast<uint32_t>(header_.materials.size());
        Material m;
        m.name = std::string(name);
        header_.materials.push_back(std::move(m));
        defined_.push_back(false);
        material_ids_.emplace(std::string(name), index);
        return index;
    }

    // A usemtl without a name (some exporters write one for "the default material") selects
    // the material of faces before any usemtl, counted; an error under --strict.
    void use_material(std::string_view name) {
        if (name.empty() && options_.strict) fail("'usemtl' without a material name (" + mention(Setting::kStrict) + ")");
        if (decided_ && !material_) {
            ++materials_dropped_;
            return;
        }
        if (name.empty()) {
            warn(kNamelessUsemtlWarning, line_no_, line_offset_);
            name = kDefaultMaterial;
        }
        saw_material_statement_ = true;
        current_material_ = material_index(name);
        if (!defined_[current_material_] && std::string_view(kDefaultMaterial) != name) used_undefined_ = true;
    }

    // mtllib names one or more files, relative to the OBJ's directory; a name with spaces is
    // taken whole when such a file exists.
    void load_material_libraries(std::string_view rest) {
        if (rest.empty()) fail("'mtllib' without a file name");
        if (decided_ && !material_) {
            ++materials_dropped_;
            return;
        }
        saw_material_statement_ = true;
        std::vector<std::string> names;
        const std::string whole(rest);
        if (whole[0] == '/' ? file_exists(whole) : file_exists(dir_ + "/" + whole)) {
            names.push_back(whole);
        } else {
            for (std::string_view w = next_word(rest); !w.empty(); w = next_word(rest)) names.emplace_back(w);
        }
        for (std::string name : names) {
            std::string path = name[0] == '/' ? name : dir_ + "/" + name;
            if (!file_exists(path) && name.find('\\') != std::string::npos) {  // written on Windows
                std::string slashed = name;
                std::replace(slashed.begin(), slashed.end(), '\\', '/');
                const std::string again = slashed[0] == '/' ? slashed : dir_ + "/" + slashed;
                if (file_exists(again)) name = slashed, path = again;
            }
            if (std::find(libraries_.begin(), libraries_.end(), path) != libraries_.end()) continue;
            libraries_.push_back(path);
            if (!file_exists(path)) {
                missing_libraries_.push_back(path);
                continue;
            }
            header_.side_files.push_back(path);
            const size_t slash = name.find_last_of('/');
            const std::string uri_dir =
                name[0] == '/' || slash == std::string::npos ? std::string() : name.substr(0, slash + 1);
            const size_t images_before = findings_.images_read.size();
            std::vector<Material> library = read_mtl(path, uri_dir, &image_budget_, findings_);
            header_.side_files.insert(header_.side_files.end(), findings_.images_read.begin() + images_before,
                                      findings_.images_read.end());
            for (Material& m : library) {
                auto it = material_ids_.find(m.name);
                if (it == material_ids_.end()) {
                    const uint32_t index = material_index(m.name);
                    header_.materials[index] = std::move(m);
                    defined_[index] = true;
                } else if (!defined_[it->second] && !decided_) {
                    // Named by a usemtl before its library: defined now, before any face uses it.
                    header_.materials[it->second] = std::move(m);
                    defined_[it->second] = true;
                } else if (!defined_[it->second]) {
                    // Used by faces already read as a name only: they keep it.
                    defined_late_.push_back("'" + m.name + "'");
                } else if (std::find(findings_.redefined.begin(), findings_.redefined.end(), m.name) ==
                           findings_.redefined.end()) {
                    findings_.redefined.push_back(m.name);
                }
            }
        }
    }

    // Reads the pending face's corners (when not yet read) and emits its triangles from
    // polygon_next_ on. False when the chunk filled before the face was done.
    bool emit_face(TriangleChunk& chunk) {
        const size_t n = face_.size();
        const Channels& want = chunk.channels();
        const bool want_color = want.color.has_value() && color_;
        const bool want_uv = want.uv_sets > 0 && uv_;
        const bool want_normal = want.normal && normal_;
        if (n == 3 && !want_color && !want_uv && !want_normal) {  // most faces of a plain stream
            if (chunk.full()) return false;
            const size_t i = chunk.size();
            float* xyz = chunk.push_slot();
            uint64_t* ids = chunk.id_at(i);
            for (int k = 0; k < 3; ++k) {
                positions_->get(face_[k].v, xyz + 3 * k, nullptr);
                if (ids) ids[k] = face_[k].v;
            }
            if (uint32_t* m = chunk.material_at(i)) *m = material_ ? face_material_ : 0;
            return true;
        }
        if (!face_loaded_) {
            corner_xyz_.resize(3 * n);
            corner_rgb_.assign(want_color ? 3 * n : 0, 1.0f);
            corner_uv_.assign(want_uv ? 2 * n : 0, 0.0f);
            corner_normal_.assign(want_normal ? 3 * n : 0, 0.0f);
            corner_id_.resize(want.vertex_id ? n : 0);
            if (want.vertex_id && (want_uv || want_normal) && !ids_) {
                ids_ = std::make_unique<CornerIds>(options_.memory_budget_bytes);
                share_budget();
            }
            for (size_t k = 0; k < n; ++k) {
                const Corner& c = face_[k];
                positions_->get(c.v, &corner_xyz_[3 * k],
                                want_color ? reinterpret_cast<std::byte*>(&corner_rgb_[3 * k]) : nullptr);
                float record[3];
                if (want_uv && c.vt != kNone) {
                    uvs_->get(c.vt, record, nullptr);
                    corner_uv_[2 * k] = record[0];
                    corner_uv_[2 * k + 1] = record[1];
                }
                if (want_normal && c.vn != kNone) normals_->get(c.vn, &corner_normal_[3 * k], nullptr);
                if (want.vertex_id) corner_id_[k] = c.v;
            }
            triangles_.clear();
            if (n == 3)
                triangles_ = {0, 1, 2};
            else
                triangulate_polygon(corner_xyz_, triangulate_scratch_, triangles_);
            if (want.vertex_id && (want_uv || want_normal)) {
                // Ids in the order the triangles use the corners, so that an indexed writer's
                // vertices (in id order) come in the order its faces first use them.
                id_done_.assign(n, 0);
                for (uint32_t k : triangles_) {
                    if (id_done_[k]) continue;
                    id_done_[k] = 1;
                    const Corner& c = face_[k];
                    corner_id_[k] = ids_->id(c.v, want_uv ? c.vt : kNone, want_normal ? c.vn : kNone);
                }
            }
            face_loaded_ = true;
        }
        for (; polygon_next_ + 2 < n; ++polygon_next_) {
            if (chunk.full()) return false;
            const size_t i = chunk.size();
            float* xyz = chunk.push_slot();
            float* normal = want_normal ? chunk.normal_at(i) : nullptr;
            float* rgba = want_color ? chunk.color_at(i) : nullptr;
            float* uv = want_uv ? chunk.uv_at(i, 0) : nullptr;
            uint64_t* ids = chunk.id_at(i);
            for (int k = 0; k < 3; ++k) {
                const uint32_t c = triangles_[3 * polygon_next_ + k];
                std::memcpy(xyz + 3 * k, &corner_xyz_[3 * c], 3 * sizeof(float));
                if (normal) std::memcpy(normal + 3 * k, &corner_normal_[3 * c], 3 * sizeof(float));
                if (rgba) std::memcpy(rgba + 4 * k, &corner_rgb_[3 * c], 3 * sizeof(float));  // alpha stays 1
                if (uv) std::memcpy(uv + 2 * k, &corner_uv_[2 * c], 2 * sizeof(float));
                if (ids) ids[k] = corner_id_[c];
            }
            if (uint32_t* m = chunk.material_at(i)) *m = material_ ? face_material_ : 0;
        }
        return true;
    }

    // The notes for `info` and the commands' warnings: MTL findings at once, counts as they
    // stand (once more at the end of the input).
    void publish_notes() {
        auto& notes = header_.notes;
        std::erase_if(notes, [](const auto& n) { return n.first == kObjWarningNote; });
        auto add = [&](std::string text) { notes.emplace_back(kObjWarningNote, std::move(text)); };
        if (short_faces_) add(plural(short_faces_, "face", "faces") + " with fewer than 3 corners skipped");
        if (lines_and_points_)
            add(plural(lines_and_points_, "line or point statement ('l', 'p')",
                       "line and point statements ('l', 'p')") +
                " skipped: meshstream reads faces");
        if (free_form_)
            add(plural(free_form_, "free-form geometry statement", "free-form geometry statements") +
                " (curv, surf, ...) skipped: meshstream reads polygon faces");
        if (unknown_)
            add(plural(unknown_, "unknown statement", "unknown statements") + " skipped (the first: " + first_unknown_ +
                ")");
        if (corners_without_uv_)
            add(plural(corners_without_uv_, "face corner", "face corners") +
                " without a texture coordinate in a file whose first face has them: given (0, 0)");
        if (corners_without_normal_)
            add(plural(corners_without_normal_, "face corner", "face corners") +
                " without a normal in a file whose first face has them: given (0, 0, 0)");
        if (vertices_without_color_)
            add(plural(vertices_without_color_, "vertex", "vertices") +
                " without a colour in a file whose first vertex has one: given white (1, 1, 1)");
        if (uv_faces_dropped_)
            add("texture coordinates of " + plural(uv_faces_dropped_, "face", "faces") +
                " dropped: the first face has none, and the first face decides");
        if (normal_faces_dropped_)
            add("normals of " + plural(normal_faces_dropped_, "face", "faces") +
                " dropped: the first face has none, and the first face decides");
        if (colors_dropped_)
            add("colours of " + plural(colors_dropped_, "vertex", "vertices") +
                " dropped: the first vertex has none, and the first vertex decides");
        if (materials_dropped_)
            add(plural(materials_dropped_, "mtllib or usemtl statement", "mtllib and usemtl statements") +
                " after the first face dropped: materials are read when mtllib or usemtl comes before it");
        for (const std::string& path : missing_libraries_)
            add("material library " + path + " not found: materials kept by name only");
        if (used_undefined_) {
            std::vector<std::string> names;
            for (size_t i = 0; i < header_.materials.size(); ++i)
                if (!defined_[i] && header_.materials[i].name != kDefaultMaterial)
                    names.push_back("'" + header_.materials[i].name + "'");
            if (!names.empty() && !(missing_libraries_.size() == libraries_.size() && !libraries_.empty()))
                add("materials used but defined in no material library, kept by name only: " + joined(names));
        }
        if (!defined_late_.empty())
            add("materials defined by an mtllib after faces used them, kept by name only: " + joined(defined_late_));
        if (!findings_.missing_images.empty())
            add("texture images not found, kept by name only: " + joined(findings_.missing_images));
        if (!findings_.unloaded_images.empty())
            add("texture images past " + mention(Setting::kMemory) + " not loaded, kept by name only: " + joined(findings_.unloaded_images));
        if (!findings_.skipped_keywords.empty())
            add("material statements not kept: " + joined(findings_.skipped_keywords, 12) +
                " (meshstream keeps Kd, d or Tr, and map_Kd)");
        if (!findings_.redefined.empty()) {
            std::vector<std::string> names;
            for (const std::string& n : findings_.redefined) names.push_back("'" + n + "'");
            add("materials defined more than once, the first definition kept: " + joined(names));
        }
    }

    ByteSource& src_;
    ReadOptions options_;
    std::string dir_;  // where mtllib names are looked for
    LineReader lines_{src_, /*join_continuations=*/true};
    std::string_view line_;
    uint64_t line_no_ = 0, line_offset_ = 0;  // where line_ began
    bool noted_unterminated_ = false;

    // Tables (created by their first statement) and what the first face decided.
    std::unique_ptr<VertexTable> positions_, uvs_, normals_;  // x y z (+ r g b); u v 0; x y z
    std::unique_ptr<CornerIds> ids_;
    uint64_t uv_count_ = 0, normal_count_ = 0;  // vt and vn statements, kept or not
    bool decided_ = false, color_ = false, uv_ = false, normal_ = false, material_ = false;
    bool saw_material_statement_ = false;

    // Materials.
    std::unordered_map<std::string, uint32_t> material_ids_;
    std::vector<bool> defined_;  // by an MTL file
    uint32_t current_material_ = kNoMaterial;
    uint64_t image_budget_;
    std::vector<std::string> libraries_, missing_libraries_, defined_late_;
    MtlFindings findings_;
    bool used_undefined_ = false;

    // The face being emitted.
    std::vector<Corner> face_;
    uint32_t face_material_ = 0;
    bool face_pending_ = false, face_loaded_ = false;
    size_t polygon_next_ = 0;  // next triangle of face_ to emit
    std::vector<float> corner_xyz_, corner_rgb_, corner_uv_, corner_normal_;
    std::vector<uint64_t> corner_id_;
    std::vector<uint8_t> id_done_;
    std::vector<uint32_t> triangles_;
    TriangulateScratch triangulate_scratch_;

    // What was skipped or filled in, for the warnings.
    uint64_t short_faces_ = 0, lines_and_points_ = 0, free_form_ = 0, unknown_ = 0;
    std::string first_unknown_;
    uint64_t corners_without_uv_ = 0, corners_without_normal_ = 0, vertices_without_color_ = 0;
    uint64_t uv_faces_dropped_ = 0, normal_faces_dropped_ = 0, colors_dropped_ = 0, materials_dropped_ = 0;
    bool published_at_end_ = false;
};

// ---------------------------------------------------------------- writer

// The output's name without ".gz" and its extension: "<dir>/out" for "<dir>/out.obj.gz".
std::string output_stem(std::string path) {
    if (path.size() > 3 && path.ends_with(".gz")) path.resize(path.size() - 3);
    const size_t slash = path.find_last_of('/');
    const size_t dot = path.find_last_of('.');
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) path.resize(dot);
    return path;
}

// True when the OBJ at `obj_path` names `mtl_name` in an mtllib statement among its first
// 64 KiB (where this writer puts it). Unreadable: false.
bool obj_uses_library(const std::string& obj_path, const std::string& mtl_name) {
    std::string text;
    try {
        const std::unique_ptr<ByteSource> source = ByteSource::open(obj_path);
        text.resize(64 << 10);
        text.resize(source->read(text.data(), text.size()));
    } catch (const Error&) {
        return false;
    }
    std::string_view rest = text;
    while (!rest.empty()) {
        const size_t nl = rest.find('\n');
        std::string_view line = rest.substr(0, nl);
        rest = nl == std::string_view::npos ? std::string_view() : rest.substr(nl + 1);
        std::string_view args = line;
        if (next_word(args) == "mtllib" && trim_blanks(args) == mtl_name) return true;
    }
    return false;
}

// The material library beside an output may replace only an earlier output's own library:
// one that an existing OBJ of the output's name uses. Anything else (another model's library,
// perhaps the input's) is refused before any work.
void check_library_path(const std::string& obj_path, const std::string& mtl_path) {
    if (!file_exists(mtl_path)) return;
    if (!file_exists(obj_path))
        throw Error(obj_path, "its material library would replace " + mtl_path +
                                  ", which exists but belongs to no earlier " + obj_path +
                                  " (another model's materials?): move it or choose another name");
    if (!obj_uses_library(obj_path, base_name(mtl_path)))
        throw Error(obj_path, "its material library would replace " + mtl_path + ", which the existing " + obj_path +
                                  " does not name in an mtllib (another model's materials?): move it or choose another "
                                  "name");
}

// A file name from a texture's uri: its last path part with every byte but letters, digits,
// '.', '-' and '_' made '_'; empty when nothing usable is left.
std::string safe_file_name(std::string_view uri) {
    if (uri.starts_with("data:")) return {};
    const size_t cut = uri.find_last_of("/\\");
    if (cut != std::string_view::npos) uri.remove_prefix(cut + 1);
    std::string out;
    for (char c : uri) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                        c == '-' || c == '_';
        out += ok ? c : '_';
    }
    if (out.empty() || out[0] == '.' || out.find_first_not_of("._") == std::string::npos) return {};
    return out;
}

// "tex.png" -> "tex_2.png".
std::string numbered(const std::string& name, int k) {
    const size_t dot = name.find_last_of('.');
    if (dot == std::string::npos || dot == 0) return name + "_" + std::to_string(k);
    return name.substr(0, dot) + "_" + std::to_string(k) + name.substr(dot);
}

bool file_has_bytes(const std::string& path, std::span<const std::byte> bytes) {
    struct stat st;
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode) || static_cast<uint64_t>(st.st_size) != bytes.size())
        return false;
    try {
        const std::unique_ptr<ByteSource> source = ByteSource::open(path);
        if (source->gzip()) return false;  // the source would hand back the decoded bytes
        std::vector<std::byte> buf(64 << 10);
        size_t done = 0;
        for (size_t n; (n = source->read(buf.data(), buf.size())) > 0; done += n)
            if (done + n > bytes.size() || std::memcmp(buf.data(), bytes.data() + done, n) != 0) return false;
        return done == bytes.size();
    } catch (const Error&) {
        return false;
    }
}

bool path_exists(const std::string& path) {
    struct stat st;
    return ::lstat(path.c_str(), &st) == 0;
}

class ObjWriter : public Writer {
public:
    ObjWriter(ByteSink& sink, const WriteOptions& options)
        : sink_(sink),
          options_(options),
          welder_(options.memory_budget_bytes, options.tmpdir, sink.name(), options.channels),
          materials_(std::move(options_.materials)) {  // with its images: held once
        const Channels& c = options_.channels;
        normal_ = c.normal;
        color_ = c.color.has_value();
        uv_ = c.uv_sets > 0;
        material_ = c.material;
        // Written in place (stdout, a pipe, a device), the OBJ has no directory entry that an
        // .mtl could sit beside: materials are kept as usemtl names only.
        side_files_ = material_ && !sink.in_place();
        if (side_files_) {
            mtl_path_ = output_stem(sink.name()) + ".mtl";
            check_library_path(sink.name(), mtl_path_);
        }
        if (material_) runs_ = std::make_unique<TempFile>(options_.tmpdir, "meshstream-materials");
    }

    void write_chunk(const TriangleChunk& chunk) override {
        welder_.add(chunk);
        if (!material_) return;
        assert(chunk.channels().material);
        // Per-triangle materials, run-length coded: files group their faces by material.
        for (uint32_t m : chunk.materials()) {
            if (m == run_.material && run_.count > 0) {
                ++run_.count;
                continue;
            }
            if (run_.count > 0) runs_->write(&run_, sizeof run_);
            run_ = Run{m, 0, 1};
        }
    }

    // The table only grows at its end: the entries (and images) held already stay.
    void materials_updated(const std::vector<Material>& materials) override {
        if (materials.size() > materials_.size())
            materials_.insert(materials_.end(), materials.begin() + static_cast<ptrdiff_t>(materials_.size()),
                              materials.end());
    }

    void finish_output() override;

    std::vector<std::string> format_notes() const override { return notes_; }

private:
    struct Run {
        uint32_t material = 0, pad = 0;
        uint64_t count = 0;
    };
    struct TextureFile {
        std::string name;  // in the output's directory
        const Material* source = nullptr;
        bool write = false;  // false: an identical file is there already
    };

    // Unique one-line names for the materials.
    std::vector<std::string> material_names() const;
    // The texture file each material's map_Kd names ("" for none), and the files to write.
    std::vector<std::string> plan_textures(std::vector<TextureFile>& files);

    ByteSink& sink_;
    WriteOptions options_;
    Welder welder_;
    std::vector<Material> materials_;
    bool normal_ = false, color_ = false, uv_ = false, material_ = false, side_files_ = false;
    std::string mtl_path_;
    std::unique_ptr<TempFile> runs_;
    Run run_;
    std::vector<std::string> notes_;
};

std::vector<std::string> ObjWriter::material_names() const {
    std::vector<std::string> names;
    for (size_t i = 0; i < materials_.size(); ++i) {
        // Blanks at the ends dropped; a line break, as every other control byte, becomes '_'.
        std::string_view trimmed = materials_[i].name;
        const auto end_blank = [](char c) { return c != '\n' && is_blank(c); };
        while (!trimmed.empty() && end_blank(trimmed.front())) trimmed.remove_prefix(1);
        while (!trimmed.empty() && end_blank(trimmed.back())) trimmed.remove_suffix(1);
        std::string base;
        for (char c : trimmed) {
            const auto u = static_cast<unsigned char>(c);
            base += u < 0x20 || u == 0x7f ? '_' : c;
        }
        if (base.empty()) base = "material_" + std::to_string(i);
        std::string name = base;
        for (int k = 2; std::find(names.begin(), names.end(), name) != names.end(); ++k)
            name = base + "_" + std::to_string(k);
        names.push_back(name);
    }
    return names;
}

std::vector<std::string> ObjWriter::plan_textures(std::vector<TextureFile>& files) {
    const std::string dir = parent_dir(sink_.name());
    const std::string stem = base_name(output_stem(sink_.name()));
    std::vector<std::string> map(materials_.size());
    for (size_t i = 0; i < materials_.size(); ++i) {
        const Material& m = materials_[i];
        if (!m.texture) continue;
        const Texture& t = *m.texture;
        if (t.bytes.empty()) {
            // Not loaded when read (missing, or past --memory): named as the input named it.
            map[i] = t.uri;
            notes_.push_back(sink_.name() + ": texture '" + t.uri + "' of material '" + m.name +
                             "' was not read with the input: " + base_name(mtl_path_) +
                             " names it as the input did, and it is not copied");
            continue;
        }
        // The same image for several materials is one file.
        auto same = std::find_if(files.begin(), files.end(), [&](const TextureFile& f) {
            return f.source->texture->bytes == t.bytes && f.source->texture->uri == t.uri;
        });
        if (same != files.end()) {
            map[i] = same->name;
            continue;
        }
        std::string base = safe_file_name(t.uri);
        if (base.empty()) {
            const std::string ext = t.mime_type == "image/png" ? ".png" : t.mime_type == "image/jpeg" ? ".jpg" : ".bin";
            base = stem + "_texture" + std::to_string(i) + ext;
        }
        // Never over another file: an identical one is used as it is, anything else (another
        // image, the input's files, the outputs themselves) gives a numbered name.
        std::string name = base;
        for (int k = 2;; ++k) {
            const std::string path = dir + "/" + name;
            const bool taken_here =
                std::any_of(files.begin(), files.end(), [&](const TextureFile& f) { return f.name == name; });
            const bool is_output = path == mtl_path_ || name == base_name(sink_.name()) || name == base_name(mtl_path_);
            if (!taken_here && !is_output) {
                if (!path_exists(path)) {
                    files.push_back({name, &m, true});
                    break;
                }
                if (file_has_bytes(path, t.bytes)) {
                    files.push_back({name, &m, false});
                    break;
                }
            }
            name = numbered(base, k);
        }
        map[i] = name;
    }
    return map;
}

void ObjWriter::finish_output() {
    welder_.finish();
    if (material_ && run_.count > 0) runs_->write(&run_, sizeof run_);
    const std::vector<std::string> names = material_names();
    std::vector<TextureFile> texture_files;
    std::vector<std::string> texture_names;
    if (side_files_) texture_names = plan_textures(texture_files);
    if (material_ && !side_files_)
        notes_.push_back(sink_.name() +
                         ": materials are written as 'usemtl' names only: their colours and textures "
                         "need an .mtl file beside the output, which a stream cannot have");

    std::string out = "# generated by meshstream\n";
    if (options_.sorted_axis) out += "# " + std::string(kSortMarker) + char('x' + *options_.sorted_axis) + "\n";
    std::string_view text = options_.comment;
    while (!text.empty()) {
        size_t nl = text.find('\n');
        out += "# " + std::string(text.substr(0, nl)) + "\n";
        if (nl == std::string_view::npos) break;
        text.remove_prefix(nl + 1);
    }
    if (side_files_) out += "mtllib " + base_name(mtl_path_) + "\n";

    // One v (with its colour), vt and vn per welded vertex: the indices of a corner are then
    // all the same, and a seam's corners are different vertices.
    const CornerLayout& layout = welder_.layout();
    std::vector<float> xyz(3 * 8192);
    std::vector<std::byte> attributes(std::max<size_t>(layout.bytes(), 1) * 8192);
    while (size_t n = welder_.next_vertices(xyz, attributes)) {
        for (size_t i = 0; i < n; ++i) {
            float normal[3], rgba[4], uv[2 * kMaxUvSets];
            if (layout.bytes() > 0) layout.unpack_values(&attributes[layout.bytes() * i], normal, rgba, uv, nullptr);
            // Assembled in a buffer, one append a vertex: at most 13 numbers of 24 characters.
            char line[384];
            char* p = line;
            auto put = [&p](float value) {
                *p++ = ' ';
                p = std::to_chars(p, p + 24, value).ptr;
            };
            *p++ = 'v';
            for (int a = 0; a < 3; ++a) put(xyz[3 * i + a]);
            if (color_)
                for (int a = 0; a < 3; ++a) put(rgba[a]);
            *p++ = '\n';
            if (uv_) {
                *p++ = 'v', *p++ = 't';
                put(uv[0]);
                put(uv[1]);
                *p++ = '\n';
            }
            if (normal_) {
                *p++ = 'v', *p++ = 'n';
                for (int a = 0; a < 3; ++a) put(normal[a]);
                *p++ = '\n';
            }
            out.append(line, p);
        }
        sink_.write(out);
        out.clear();
    }

    // Faces in input order, a usemtl where the material changes.
    uint64_t triangle = 0, run_left = 0, run_offset = 0;
    std::vector<uint32_t> idx(3 * 8192);
    while (size_t n = welder_.next_indices(idx)) {
        for (size_t t = 0; t + 2 < n; t += 3, ++triangle) {
            if (material_ && run_left == 0) {
                Run run;
                runs_->read_at(run_offset, &run, sizeof run);
                run_offset += sizeof run;
                run_left = run.count;
                if (run.material >= materials_.size())
                    throw Error(sink_.name(), "triangle " + std::to_string(triangle) + " has material " +
                                                  std::to_string(run.material) + ", past the material table of " +
                                                  std::to_string(materials_.size()));
                out += "usemtl " + names[run.material] + "\n";
            }
            --run_left;
            char line[128];  // "f" and 3 corners of up to 3 numbers of 10 digits
            char* p = line;
            *p++ = 'f';
            for (int k = 0; k < 3; ++k) {
                *p++ = ' ';
                char* number = p;
                p = std::to_chars(p, p + 10, idx[t + k] + uint64_t{1}).ptr;
                const size_t digits = static_cast<size_t>(p - number);
                if (uv_ || normal_) {  // "i/i", "i//i", "i/i/i": one vertex per corner
                    *p++ = '/';
                    if (uv_) p = std::copy_n(number, digits, p);
                    if (normal_) {
                        *p++ = '/';
                        p = std::copy_n(number, digits, p);
                    }
                }
            }
            *p++ = '\n';
            out.append(line, p);
        }
        sink_.write(out);
        out.clear();
    }
    if (!side_files_) return;

    // The side files go through their own ByteSinks (temporary names beside the targets). All
    // are written out in full before any is renamed, so a full disk leaves none behind; the
    // caller renames the OBJ right after them.
    const std::string dir = parent_dir(sink_.name());
    std::vector<std::unique_ptr<ByteSink>> sides;
    for (const TextureFile& f : texture_files) {
        if (!f.write) continue;
        sides.push_back(ByteSink::open(dir + "/" + f.name));
        sides.back()->write(f.source->texture->bytes.data(), f.source->texture->bytes.size());
    }
    sides.push_back(ByteSink::open(mtl_path_));
    sides.back()->write(write_mtl(materials_, names, texture_names));
    for (auto& s : sides) s->finish_writing();
    sink_.finish_writing();
    for (auto& s : sides) s->commit();
}

std::unique_ptr<Reader> open_obj_reader(ByteSource& source, const ReadOptions& options) {
    return std::make_unique<ObjReader>(source, options);
}

std::unique_ptr<Writer> open_obj_writer(ByteSink& sink, const WriteOptions& options) {
    return std::make_unique<ObjWriter>(sink, options);
}

// OBJ holds normals, RGB colours, one texture coordinate set and materials.
Channels obj_keep_channels(const Channels& in, const WriteOptions&) {
    Channels out;
    out.normal = in.normal;
    if (in.color) {
        out.color = in.color;
        out.color->alpha = false;
    }
    out.uv_sets = std::min(in.uv_sets, 1);
    out.material = in.material;
    out.vertex_id = in.vertex_id;
    return out;
}

// The material library beside the output. Texture images are not listed: the writer never
// writes over a file of other bytes (it numbers the name), and one with the same bytes (the
// input's own image, when writing into its directory) is used as it is.
std::vector<std::string> obj_side_files(const std::string& path, const WriteOptions& options) {
    if (!options.channels.material || is_stream(path)) return {};
    return {output_stem(path) + ".mtl"};
}

}  // namespace

bool guess_obj(std::span<const std::byte> head) {
    if (head.empty()) return false;
    for (std::byte b : head) {
        unsigned char c = static_cast<unsigned char>(b);
        if (c < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\v' && c != '\f') return false;  // binary
    }
    std::string_view text(reinterpret_cast<const char*>(head.data()), head.size());
    if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);  // UTF-8 byte order mark
    static constexpr std::string_view kKeywords[] = {"v", "vt", "vn",     "vp",     "f", "o",
                                                     "g", "s",  "usemtl", "mtllib", "l", "p"};
    while (!text.empty()) {
        size_t nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
        std::string_view rest = line;
        std::string_view key = next_word(rest);
        if (key.empty() || key[0] == '#') continue;
        for (std::string_view k : kKeywords)
            if (key == k) return true;
        return false;
    }
    return true;  // only comments and blank lines
}

const Format kObjFormat = {
    "obj",
    "obj",
    "Wavefront OBJ (v, vt, vn, f; materials from and to an .mtl beside it)",
    nullptr,  // no magic bytes
    &open_obj_reader,
    &open_obj_writer,
    0,
    &guess_obj,
    &obj_keep_channels,
    &obj_side_files,
};

}  // namespace meshstream::io
