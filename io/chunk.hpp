// The triangle-soup chunk: the one currency between readers, the decimator, the sorter and
// writers. Plain data, fixed capacity, allocated once and reused for a whole stream (PDAL's
// StreamPointTable, handed over a block at a time). Triangle i is xyz()[9*i .. 9*i+8]:
// v0.xyz, v1.xyz, v2.xyz.
//
// Optional channels ride along when the producer has them, described once per stream by
// `Channels` (a reader's header, a writer's options). Per corner: normal (float3), colour
// (RGBA as float, 0..1 for integer sources, with the source's type and whether it had alpha),
// texture coordinates (float2 per set), named extra scalars (double, with the source's type),
// vertex ids (uint64: equal ids mean the same vertex, so indexed writers need not weld again).
// Per triangle: a material index into the stream's material table (MeshHeader::materials) and
// named extra scalars. A channel that is absent allocates nothing and costs nothing.
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace meshstream::io {

// A scalar type as a file stores it (PLY's property types, Draco's and glTF's component types).
enum class ScalarType : uint8_t { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };
// "uchar", "float", ... (PLY's names).
const char* scalar_type_name(ScalarType type);
// Bytes per value.
size_t scalar_type_bytes(ScalarType type);

// How the source stored its colour. Values travel as float: integer channels as value / max
// (255 or 65535), which converts back exactly; float channels as they are.
struct ColorFormat {
    ScalarType type = ScalarType::kUInt8;  // kUInt8, kUInt16 or kFloat32
    bool alpha = false;                    // the source had an alpha channel (else alpha = 1)
    bool operator==(const ColorFormat&) const = default;
};

// A colour component (nominally 0..1) as an integer channel of `max` (255 or 65535) stores it:
// clamped, rounded half away from zero; NaN is 0. Inline: it runs for every corner written.
// The product is below 65536 with a float's 24 bits, so adding 0.5 in double is exact and
// truncating rounds as std::lround would.
template <class T>
T color_to_unorm(float v, float max) {
    if (!(v > 0.0f)) return 0;
    if (v >= 1.0f) return static_cast<T>(max);
    return static_cast<T>(double(v * max) + 0.5);
}

// A named scalar channel (PLY "intensity", "confidence", a face "label"; Draco generic).
struct ScalarChannel {
    std::string name;
    ScalarType type = ScalarType::kFloat32;  // as the source stored it; values travel as double
    bool operator==(const ScalarChannel&) const = default;
};

inline constexpr int kMaxUvSets = 4;

struct Channels {
    // Per corner.
    bool normal = false;                        // 3 × float
    std::optional<ColorFormat> color;           // 4 × float (RGBA)
    int uv_sets = 0;                            // 2 × float each (TEXCOORD_0, ...), 0..kMaxUvSets
    std::vector<ScalarChannel> vertex_scalars;  // 1 × double each
    bool vertex_id = false;                     // 1 × uint64; equal ids mean the same vertex
    // Per triangle.
    bool material = false;                    // 1 × uint32, an index into the material table
    std::vector<ScalarChannel> face_scalars;  // 1 × double each

    bool operator==(const Channels&) const = default;
    // Positions and vertex ids (what the decimator emits).
    static Channels ids_only() {
        Channels c;
        c.vertex_id = true;
        return c;
    }
    // True when any channel but vertex ids is present (what a positions-only consumer drops).
    bool has_attributes() const {
        return normal || color || uv_sets > 0 || !vertex_scalars.empty() || material || !face_scalars.empty();
    }
};

// Kinds of channel, to say which a reader should fill (ReadOptions::channels); the groups of
// `--drop normals,colors,uvs,extra`.
struct ChannelKinds {
    bool normals = true;
    bool colors = true;
    bool uvs = true;
    bool extras = true;  // named vertex and face scalars
    bool materials = true;
    static ChannelKinds none() { return {false, false, false, false, false}; }
    // The channels of `c` of these kinds (and its vertex ids).
    Channels of(const Channels& c) const {
        Channels out;
        out.normal = normals && c.normal;
        if (colors) out.color = c.color;
        out.uv_sets = uvs ? c.uv_sets : 0;
        if (extras) out.vertex_scalars = c.vertex_scalars, out.face_scalars = c.face_scalars;
        out.material = materials && c.material;
        out.vertex_id = c.vertex_id;
        return out;
    }
};

// The channels present in `a` but not in `b`, in words ("normals, colour alpha, texture
// coordinates, 'intensity'"); empty when `b` holds everything of `a` (vertex ids ignored).
std::string describe_missing(const Channels& a, const Channels& b);
// The channels of `a` that `b` also has (per field; a colour keeps a's format, alpha only
// when both have it; scalars by name; uv sets the smaller count).
Channels intersect(const Channels& a, const Channels& b);

class TriangleChunk {
public:
    static constexpr size_t kDefaultCapacity = 16384;  // 576 KiB of positions

    // Throws std::invalid_argument for a capacity of 0 (readers could then never make progress)
    // or more than kMaxUvSets uv sets.
    explicit TriangleChunk(size_t capacity = kDefaultCapacity, Channels channels = {}) : capacity_(capacity) {
        if (capacity == 0) throw std::invalid_argument("TriangleChunk: capacity must be at least 1");
        xyz_.resize(9 * capacity);
        set_channels(std::move(channels));
    }

    size_t size() const { return size_; }
    size_t capacity() const { return capacity_; }
    bool empty() const { return size_ == 0; }
    bool full() const { return size_ == capacity_; }
    void clear() { size_ = 0; }
    const Channels& channels() const { return channels_; }

    // Re-shapes the chunk for other channels (keeps size(); new channels' slots are zero).
    void set_channels(Channels channels) {
        if (channels.uv_sets < 0 || channels.uv_sets > kMaxUvSets)
            throw std::invalid_argument("TriangleChunk: at most 4 texture coordinate sets");
        channels_ = std::move(channels);
        normal_.resize(channels_.normal ? 9 * capacity_ : 0);
        color_.resize(channels_.color ? 12 * capacity_ : 0);
        uv_.resize(6 * size_t(channels_.uv_sets) * capacity_);
        vscalar_.resize(3 * channels_.vertex_scalars.size() * capacity_);
        id_.resize(channels_.vertex_id ? 3 * capacity_ : 0);
        material_.resize(channels_.material ? capacity_ : 0);
        fscalar_.resize(channels_.face_scalars.size() * capacity_);
    }

    std::span<const float> xyz() const { return {xyz_.data(), 9 * size_}; }
    std::span<float> xyz() { return {xyz_.data(), 9 * size_}; }
    // Channel spans: triangle i's values start at i × (values per triangle); empty when absent.
    std::span<const float> normals() const { return {normal_.data(), channels_.normal ? 9 * size_ : 0}; }
    std::span<float> normals() { return {normal_.data(), channels_.normal ? 9 * size_ : 0}; }
    std::span<const float> colors() const { return {color_.data(), channels_.color ? 12 * size_ : 0}; }
    std::span<float> colors() { return {color_.data(), channels_.color ? 12 * size_ : 0}; }
    std::span<const uint64_t> vertex_ids() const { return {id_.data(), channels_.vertex_id ? 3 * size_ : 0}; }
    std::span<uint64_t> vertex_ids() { return {id_.data(), channels_.vertex_id ? 3 * size_ : 0}; }
    std::span<const uint32_t> materials() const { return {material_.data(), channels_.material ? size_ : 0}; }
    std::span<uint32_t> materials() { return {material_.data(), channels_.material ? size_ : 0}; }

    // Raw pointers to slot i's channels (i < size()); null when the channel is absent.
    float* normal_at(size_t i) { return channels_.normal ? &normal_[9 * i] : nullptr; }
    float* color_at(size_t i) { return channels_.color ? &color_[12 * i] : nullptr; }  // 3 corners × RGBA
    // Set `set` of slot i: 3 corners × (u, v). Null when the chunk has fewer sets.
    float* uv_at(size_t i, int set) {
        return set < channels_.uv_sets ? &uv_[(size_t(set) * capacity_ + i) * 6] : nullptr;
    }
    // Vertex scalar channel `c` of slot i: 3 corners.
    double* vertex_scalar_at(size_t i, size_t c) { return &vscalar_[(c * capacity_ + i) * 3]; }
    double* face_scalar_at(size_t i, size_t c) { return &fscalar_[c * capacity_ + i]; }
    uint64_t* id_at(size_t i) { return channels_.vertex_id ? &id_[3 * i] : nullptr; }
    uint32_t* material_at(size_t i) { return channels_.material ? &material_[i] : nullptr; }
    const float* normal_at(size_t i) const { return const_cast<TriangleChunk*>(this)->normal_at(i); }
    const float* color_at(size_t i) const { return const_cast<TriangleChunk*>(this)->color_at(i); }
    const float* uv_at(size_t i, int set) const { return const_cast<TriangleChunk*>(this)->uv_at(i, set); }
    const double* vertex_scalar_at(size_t i, size_t c) const {
        return const_cast<TriangleChunk*>(this)->vertex_scalar_at(i, c);
    }
    const double* face_scalar_at(size_t i, size_t c) const {
        return const_cast<TriangleChunk*>(this)->face_scalar_at(i, c);
    }
    const uint64_t* id_at(size_t i) const { return const_cast<TriangleChunk*>(this)->id_at(i); }
    const uint32_t* material_at(size_t i) const { return const_cast<TriangleChunk*>(this)->material_at(i); }

    // Appends one triangle (positions only; channel slots of the new triangle are zeroed, a
    // colour's alpha 1). Throws std::length_error when full().
    void push(const float (&tri)[9]) { std::memcpy(push_slot(), tri, sizeof tri); }

    // Appends one triangle and returns its 9 position floats to fill in place. Channel slots
    // of the new triangle are zeroed (a colour is opaque black). Throws std::length_error when full().
    float* push_slot() {
        if (full()) throw std::length_error("TriangleChunk: push into a full chunk");
        size_t i = size_++;
        if (!channels_.has_attributes() && !channels_.vertex_id) return &xyz_[9 * i];
        clear_channels(i);
        return &xyz_[9 * i];
    }

    // Copies triangle `from` of `src` (which has the same channels) into slot `to` of this
    // chunk (to < size()). `src` may be this chunk.
    void copy_triangle(size_t to, const TriangleChunk& src, size_t from);
    // Appends triangle `from` of `src` (same channels). Throws std::length_error when full().
    void push_copy(const TriangleChunk& src, size_t from) {
        if (full()) throw std::length_error("TriangleChunk: push into a full chunk");
        copy_triangle(size_++, src, from);
    }

    // Sets size directly after filling storage in bulk (n <= capacity()). Slots past the old
    // size keep whatever their channels held.
    void resize(size_t n) {
        assert(n <= capacity_);
        size_ = n;
    }
    float* xyz_storage() { return xyz_.data(); }

private:
    void clear_channels(size_t i);

    size_t capacity_;
    size_t size_ = 0;
    Channels channels_;
    std::vector<float> xyz_;
    std::vector<float> normal_;
    std::vector<float> color_;
    std::vector<float> uv_;        // set-major: set s, slot i at (s × capacity + i) × 6
    std::vector<double> vscalar_;  // channel-major, as uv_
    std::vector<uint64_t> id_;
    std::vector<uint32_t> material_;
    std::vector<double> fscalar_;  // channel-major
};

inline void TriangleChunk::clear_channels(size_t i) {
    if (channels_.normal) std::memset(&normal_[9 * i], 0, 9 * sizeof(float));
    if (channels_.color) {
        float* c = &color_[12 * i];
        for (int k = 0; k < 3; ++k) c[4 * k] = c[4 * k + 1] = c[4 * k + 2] = 0.0f, c[4 * k + 3] = 1.0f;
    }
    for (int s = 0; s < channels_.uv_sets; ++s) std::memset(uv_at(i, s), 0, 6 * sizeof(float));
    for (size_t c = 0; c < channels_.vertex_scalars.size(); ++c)
        vertex_scalar_at(i, c)[0] = vertex_scalar_at(i, c)[1] = vertex_scalar_at(i, c)[2] = 0.0;
    if (channels_.vertex_id) std::memset(&id_[3 * i], 0, 3 * sizeof(uint64_t));
    if (channels_.material) material_[i] = 0;
    for (size_t c = 0; c < channels_.face_scalars.size(); ++c) *face_scalar_at(i, c) = 0.0;
}

inline void TriangleChunk::copy_triangle(size_t to, const TriangleChunk& src, size_t from) {
    assert(src.channels_ == channels_);
    if (&src == this && to == from) return;
    std::memmove(&xyz_[9 * to], &src.xyz_[9 * from], 9 * sizeof(float));
    if (channels_.normal) std::memmove(&normal_[9 * to], &src.normal_[9 * from], 9 * sizeof(float));
    if (channels_.color) std::memmove(&color_[12 * to], &src.color_[12 * from], 12 * sizeof(float));
    for (int s = 0; s < channels_.uv_sets; ++s) std::memmove(uv_at(to, s), src.uv_at(from, s), 6 * sizeof(float));
    for (size_t c = 0; c < channels_.vertex_scalars.size(); ++c)
        std::memmove(vertex_scalar_at(to, c), src.vertex_scalar_at(from, c), 3 * sizeof(double));
    if (channels_.vertex_id) std::memmove(&id_[3 * to], &src.id_[3 * from], 3 * sizeof(uint64_t));
    if (channels_.material) material_[to] = src.material_[from];
    for (size_t c = 0; c < channels_.face_scalars.size(); ++c) *face_scalar_at(to, c) = *src.face_scalar_at(from, c);
}

// A fixed-size byte record of one corner's attributes (everything per corner but the position
// and the vertex id), for what stores vertices outside a chunk: the indexed readers' vertex
// table, the welder's keys, the sorter's runs. Colours and named scalars are packed in the
// source's type (RGBA8 takes 4 bytes, a uchar label 1; a scalar is rounded and clamped to an
// integer type's range), so a record is as small as the source's vertex. Equal values give
// equal bytes (-0 normals aside), so records compare with memcmp.
class CornerLayout {
public:
    explicit CornerLayout(const Channels& channels);
    size_t bytes() const { return bytes_; }
    // Packs corner k (0..2) of chunk triangle i into dst[bytes()].
    void pack(const TriangleChunk& chunk, size_t i, int k, std::byte* dst) const;
    // Unpacks src[bytes()] into corner k of chunk triangle i: the channels the chunk has (its
    // vertex scalars only when they are the layout's).
    void unpack(const std::byte* src, TriangleChunk& chunk, size_t i, int k) const;
    // The same from and to loose values, for readers that build a corner field by field:
    // normal[3], rgba[4] (0..1), uv[2 × sets], scalars[n]; null pointers for absent channels
    // (pack: the layout's channels must all be given; unpack: a null one is skipped).
    void pack_values(const float* normal, const float* rgba, const float* uv, const double* scalars,
                     std::byte* dst) const;
    void unpack_values(const std::byte* src, float* normal, float* rgba, float* uv, double* scalars) const;

private:
    Channels channels_;
    size_t color_bytes_ = 0;  // per component
    size_t bytes_ = 0;
};

// The same for one triangle's per-triangle attributes (material, face scalars).
class FaceLayout {
public:
    explicit FaceLayout(const Channels& channels);
    size_t bytes() const { return bytes_; }
    void pack(const TriangleChunk& chunk, size_t i, std::byte* dst) const;
    void unpack(const std::byte* src, TriangleChunk& chunk, size_t i) const;

private:
    bool material_ = false;
    size_t scalars_ = 0;
    size_t bytes_ = 0;
};

}  // namespace meshstream::io
