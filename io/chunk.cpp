// The channel descriptions, and the corner/face byte records.
#include "io/chunk.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace meshstream::io {

const char* scalar_type_name(ScalarType type) {
    switch (type) {
        case ScalarType::kInt8: return "char";
        case ScalarType::kUInt8: return "uchar";
        case ScalarType::kInt16: return "short";
        case ScalarType::kUInt16: return "ushort";
        case ScalarType::kInt32: return "int";
        case ScalarType::kUInt32: return "uint";
        case ScalarType::kFloat32: return "float";
        case ScalarType::kFloat64: return "double";
    }
    return "?";
}

size_t scalar_type_bytes(ScalarType type) {
    switch (type) {
        case ScalarType::kInt8:
        case ScalarType::kUInt8: return 1;
        case ScalarType::kInt16:
        case ScalarType::kUInt16: return 2;
        case ScalarType::kInt32:
        case ScalarType::kUInt32:
        case ScalarType::kFloat32: return 4;
        case ScalarType::kFloat64: return 8;
    }
    return 0;
}

namespace {

bool has_scalar(const std::vector<ScalarChannel>& list, const std::string& name) {
    return std::any_of(list.begin(), list.end(), [&](const ScalarChannel& s) { return s.name == name; });
}

void join(std::string& out, const std::string& item) {
    if (!out.empty()) out += ", ";
    out += item;
}

}  // namespace

std::string describe_missing(const Channels& a, const Channels& b) {
    std::string out;
    if (a.normal && !b.normal) join(out, "normals");
    if (a.color && !b.color) join(out, "colours");
    if (a.color && b.color && a.color->alpha && !b.color->alpha) join(out, "colour alpha");
    if (a.uv_sets > b.uv_sets)
        join(out, b.uv_sets == 0 ? std::string("texture coordinates")
                                 : "texture coordinate sets past " + std::to_string(b.uv_sets));
    if (a.material && !b.material) join(out, "materials");
    for (const ScalarChannel& s : a.vertex_scalars)
        if (!has_scalar(b.vertex_scalars, s.name)) join(out, "vertex property '" + s.name + "'");
    for (const ScalarChannel& s : a.face_scalars)
        if (!has_scalar(b.face_scalars, s.name)) join(out, "face property '" + s.name + "'");
    return out;
}

Channels intersect(const Channels& a, const Channels& b) {
    Channels out;
    out.normal = a.normal && b.normal;
    if (a.color && b.color) {
        out.color = a.color;
        out.color->alpha = a.color->alpha && b.color->alpha;
    }
    out.uv_sets = std::min(a.uv_sets, b.uv_sets);
    for (const ScalarChannel& s : a.vertex_scalars)
        if (has_scalar(b.vertex_scalars, s.name)) out.vertex_scalars.push_back(s);
    for (const ScalarChannel& s : a.face_scalars)
        if (has_scalar(b.face_scalars, s.name)) out.face_scalars.push_back(s);
    out.vertex_id = a.vertex_id && b.vertex_id;
    out.material = a.material && b.material;
    return out;
}

// ---- CornerLayout ----

CornerLayout::CornerLayout(const Channels& channels) : channels_(channels) {
    channels_.vertex_id = false;
    channels_.material = false;
    channels_.face_scalars.clear();
    if (channels_.normal) bytes_ += 3 * sizeof(float);
    if (channels_.color) {
        color_bytes_ = channels_.color->type == ScalarType::kUInt8    ? 1
                       : channels_.color->type == ScalarType::kUInt16 ? 2
                                                                      : 4;
        bytes_ += (channels_.color->alpha ? 4 : 3) * color_bytes_;
    }
    bytes_ += size_t(channels_.uv_sets) * 2 * sizeof(float);
    for (const ScalarChannel& c : channels_.vertex_scalars) bytes_ += scalar_type_bytes(c.type);
}

namespace {

template <class T>
std::byte* put(std::byte* dst, T v) {
    std::memcpy(dst, &v, sizeof v);
    return dst + sizeof v;
}
template <class T>
const std::byte* get(const std::byte* src, T& v) {
    std::memcpy(&v, src, sizeof v);
    return src + sizeof v;
}

// A value as an integer type T stores it: rounded to nearest, clamped to T's range; NaN is 0.
template <class T>
T to_integer(double v) {
    if (!(v == v)) return 0;
    constexpr double lo = double(std::numeric_limits<T>::min()), hi = double(std::numeric_limits<T>::max());
    return static_cast<T>(std::clamp(std::nearbyint(v), lo, hi));
}

// A named scalar in its channel's type (what a record and a file store).
std::byte* put_scalar(std::byte* dst, double v, ScalarType type) {
    switch (type) {
        case ScalarType::kInt8: return put(dst, to_integer<int8_t>(v));
        case ScalarType::kUInt8: return put(dst, to_integer<uint8_t>(v));
        case ScalarType::kInt16: return put(dst, to_integer<int16_t>(v));
        case ScalarType::kUInt16: return put(dst, to_integer<uint16_t>(v));
        case ScalarType::kInt32: return put(dst, to_integer<int32_t>(v));
        case ScalarType::kUInt32: return put(dst, to_integer<uint32_t>(v));
        case ScalarType::kFloat32: return put(dst, static_cast<float>(v));
        case ScalarType::kFloat64: return put(dst, v);
    }
    return dst;
}

template <class T>
double get_as_double(const std::byte* src) {
    T v;
    std::memcpy(&v, src, sizeof v);
    return static_cast<double>(v);
}

double get_scalar(const std::byte* src, ScalarType type) {
    switch (type) {
        case ScalarType::kInt8: return get_as_double<int8_t>(src);
        case ScalarType::kUInt8: return get_as_double<uint8_t>(src);
        case ScalarType::kInt16: return get_as_double<int16_t>(src);
        case ScalarType::kUInt16: return get_as_double<uint16_t>(src);
        case ScalarType::kInt32: return get_as_double<int32_t>(src);
        case ScalarType::kUInt32: return get_as_double<uint32_t>(src);
        case ScalarType::kFloat32: return get_as_double<float>(src);
        case ScalarType::kFloat64: return get_as_double<double>(src);
    }
    return 0;
}

// v / 255 for every 8-bit component v, as float: the division once, not for every corner.
constexpr std::array<float, 256> kUnorm8 = [] {
    std::array<float, 256> t{};
    for (int v = 0; v < 256; ++v) t[size_t(v)] = float(v) / 255.0f;
    return t;
}();

}  // namespace

void CornerLayout::pack_values(const float* normal, const float* rgba, const float* uv, const double* scalars,
                               std::byte* dst) const {
    if (channels_.normal)
        for (int a = 0; a < 3; ++a) dst = put(dst, normal[a]);
    if (channels_.color) {
        const int n = channels_.color->alpha ? 4 : 3;
        for (int a = 0; a < n; ++a) {
            if (color_bytes_ == 1)
                dst = put(dst, color_to_unorm<uint8_t>(rgba[a], 255.0f));
            else if (color_bytes_ == 2)
                dst = put(dst, color_to_unorm<uint16_t>(rgba[a], 65535.0f));
            else
                dst = put(dst, rgba[a]);
        }
    }
    for (int a = 0; a < 2 * channels_.uv_sets; ++a) dst = put(dst, uv[a]);
    for (size_t c = 0; c < channels_.vertex_scalars.size(); ++c)
        dst = put_scalar(dst, scalars[c], channels_.vertex_scalars[c].type);
}

void CornerLayout::unpack_values(const std::byte* src, float* normal, float* rgba, float* uv, double* scalars) const {
    if (channels_.normal) {
        if (normal) std::memcpy(normal, src, 3 * sizeof(float));
        src += 3 * sizeof(float);
    }
    if (channels_.color) {
        const int n = channels_.color->alpha ? 4 : 3;
        float c[4] = {0.0f, 0.0f, 0.0f, 1.0f};
        for (int a = 0; a < n; ++a) {
            if (color_bytes_ == 1) {
                c[a] = kUnorm8[std::to_integer<uint8_t>(*src++)];
            } else if (color_bytes_ == 2) {
                uint16_t v;
                src = get(src, v);
                c[a] = float(v) / 65535.0f;
            } else {
                src = get(src, c[a]);
            }
        }
        if (rgba) std::memcpy(rgba, c, sizeof c);
    }
    if (channels_.uv_sets > 0) {
        if (uv) std::memcpy(uv, src, 2 * sizeof(float) * size_t(channels_.uv_sets));
        src += 2 * sizeof(float) * size_t(channels_.uv_sets);
    }
    if (scalars)
        for (size_t c = 0; c < channels_.vertex_scalars.size(); ++c) {
            const ScalarType type = channels_.vertex_scalars[c].type;
            scalars[c] = get_scalar(src, type);
            src += scalar_type_bytes(type);
        }
}

void CornerLayout::pack(const TriangleChunk& chunk, size_t i, int k, std::byte* dst) const {
    if (bytes_ == 0) return;
    float uv[2 * kMaxUvSets];
    for (int s = 0; s < channels_.uv_sets; ++s) std::memcpy(uv + 2 * s, chunk.uv_at(i, s) + 2 * k, 2 * sizeof(float));
    double scalars_small[16];
    std::vector<double> scalars_big;
    double* scalars = scalars_small;
    const size_t ns = channels_.vertex_scalars.size();
    if (ns > 16) scalars_big.resize(ns), scalars = scalars_big.data();
    for (size_t c = 0; c < ns; ++c) scalars[c] = chunk.vertex_scalar_at(i, c)[k];
    pack_values(channels_.normal ? chunk.normal_at(i) + 3 * k : nullptr,
                channels_.color ? chunk.color_at(i) + 4 * k : nullptr, uv, scalars, dst);
}

void CornerLayout::unpack(const std::byte* src, TriangleChunk& chunk, size_t i, int k) const {
    if (bytes_ == 0) return;
    const Channels& has = chunk.channels();
    float uv[2 * kMaxUvSets];
    double scalars_small[16];
    std::vector<double> scalars_big;
    double* scalars = nullptr;
    const size_t ns = channels_.vertex_scalars.size();
    const bool want_scalars = ns > 0 && has.vertex_scalars == channels_.vertex_scalars;
    if (want_scalars) {
        scalars = scalars_small;
        if (ns > 16) scalars_big.resize(ns), scalars = scalars_big.data();
    }
    unpack_values(src, has.normal ? chunk.normal_at(i) + 3 * k : nullptr,
                  has.color ? chunk.color_at(i) + 4 * k : nullptr, uv, scalars);
    for (int s = 0; s < std::min(channels_.uv_sets, has.uv_sets); ++s)
        std::memcpy(chunk.uv_at(i, s) + 2 * k, uv + 2 * s, 2 * sizeof(float));
    if (want_scalars)
        for (size_t c = 0; c < ns; ++c) chunk.vertex_scalar_at(i, c)[k] = scalars[c];
}

// ---- FaceLayout ----

FaceLayout::FaceLayout(const Channels& channels)
    : material_(channels.material), scalars_(channels.face_scalars.size()) {
    bytes_ = (material_ ? sizeof(uint32_t) : 0) + scalars_ * sizeof(double);
}

void FaceLayout::pack(const TriangleChunk& chunk, size_t i, std::byte* dst) const {
    if (material_) dst = put(dst, *chunk.material_at(i));
    for (size_t c = 0; c < scalars_; ++c) dst = put(dst, *chunk.face_scalar_at(i, c));
}

void FaceLayout::unpack(const std::byte* src, TriangleChunk& chunk, size_t i) const {
    if (material_) src = get(src, *chunk.material_at(i));
    for (size_t c = 0; c < scalars_; ++c) src = get(src, *chunk.face_scalar_at(i, c));
}

}  // namespace meshstream::io
