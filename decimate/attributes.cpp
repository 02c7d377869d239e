// The attribute vector of a corner: a stream's channels gathered into m numbers and back.
#include "decimate/attributes.hpp"

#include "io/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace meshstream::decimate {

AttributeLayout::AttributeLayout(const io::Channels& channels, const AttributeWeights& weights) {
    auto checked = [](double w, const std::string& what) {
        if (!(w >= 0) || !std::isfinite(w)) {
            char value[32];
            std::snprintf(value, sizeof value, "%g", w);
            throw io::OptionError(io::Setting::kWeights,
                                  "attribute weight of " + what + " must be a finite number >= 0, got " + value);
        }
        return w * w;
    };
    const double normal = checked(weights.normal, "normals"), color = checked(weights.color, "colours"),
                 uv = checked(weights.uv, "texture coordinates");
    channels_.vertex_id = true;
    if (channels.normal) {
        channels_.normal = true;
        normal_ = size_;
        size_ += 3;
        omega_.insert(omega_.end(), 3, normal);
    }
    if (channels.color) {
        channels_.color = channels.color;
        color_ = size_;
        color_size_ = channels.color->alpha ? 4 : 3;
        size_ += color_size_;
        omega_.insert(omega_.end(), size_t(color_size_), color);
    }
    if (channels.uv_sets > 0) {
        channels_.uv_sets = channels.uv_sets;
        uv_ = size_;
        size_ += 2 * channels.uv_sets;
        omega_.insert(omega_.end(), size_t(2 * channels.uv_sets), uv);
    }
    if (!channels.vertex_scalars.empty()) {
        channels_.vertex_scalars = channels.vertex_scalars;
        scalar_ = size_;
        size_ += int(channels.vertex_scalars.size());
        omega_.insert(omega_.end(), channels.vertex_scalars.size(), 0.0);
    }
    for (const auto& [name, w] : weights.scalars) {
        const auto& s = channels.vertex_scalars;
        const auto it = std::find_if(s.begin(), s.end(), [&](const io::ScalarChannel& c) { return c.name == name; });
        if (it == s.end()) throw io::OptionError(io::Setting::kWeights, "no vertex scalar '" + name + "' to weigh");
        omega_[size_t(scalar_) + size_t(it - s.begin())] = checked(w, "'" + name + "'");
    }
    channels_.material = channels.material;
    channels_.face_scalars = channels.face_scalars;
    weighted_ = std::any_of(omega_.begin(), omega_.end(), [](double w) { return w > 0; });
}

bool AttributeLayout::carried_by(const io::Channels& c) const {
    return (!channels_.normal || c.normal) && (!channels_.color || c.color) && c.uv_sets >= channels_.uv_sets &&
           c.vertex_scalars.size() >= channels_.vertex_scalars.size() && (!channels_.material || c.material) &&
           c.face_scalars.size() >= channels_.face_scalars.size();
}

void AttributeLayout::gather(const io::TriangleChunk& chunk, size_t i, int corner, float* out) const {
    if (normal_ >= 0) std::copy_n(chunk.normal_at(i) + 3 * corner, 3, out + normal_);
    if (color_ >= 0) std::copy_n(chunk.color_at(i) + 4 * corner, color_size_, out + color_);
    for (int s = 0; s < channels_.uv_sets; ++s) std::copy_n(chunk.uv_at(i, s) + 2 * corner, 2, out + uv_ + 2 * s);
    for (size_t c = 0; c < channels_.vertex_scalars.size(); ++c)
        out[size_t(scalar_) + c] = float(chunk.vertex_scalar_at(i, c)[corner]);
}

void AttributeLayout::scatter(const float* in, io::TriangleChunk& chunk, size_t i, int corner) const {
    if (normal_ >= 0) {
        const float* n = in + normal_;
        const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
        float* out = chunk.normal_at(i) + 3 * corner;
        for (int k = 0; k < 3; ++k) out[k] = len > 0 ? float(n[k] / len) : 0.0f;
    }
    if (color_ >= 0) {
        float* out = chunk.color_at(i) + 4 * corner;
        for (int k = 0; k < color_size_; ++k) out[k] = std::clamp(in[color_ + k], 0.0f, 1.0f);
    }
    for (int s = 0; s < channels_.uv_sets; ++s) std::copy_n(in + uv_ + 2 * s, 2, chunk.uv_at(i, s) + 2 * corner);
    for (size_t c = 0; c < channels_.vertex_scalars.size(); ++c)
        chunk.vertex_scalar_at(i, c)[corner] = in[size_t(scalar_) + c];
}

}  // namespace meshstream::decimate
