// The triangle-soup chunk: the one currency between readers, the decimator, the sorter and
// writers. Plain data, fixed capacity, allocated once and reused for a whole stream (PDAL's
// StreamPointTable, handed over a block at a time). Triangle i is xyz()[9*i .. 9*i+8]:
// v0.xyz, v1.xyz, v2.xyz.
//
// Optional per-corner channels ride along when the producer has them: colour (RGB8), normals
// (float3) and vertex ids (uint64, set by producers that know vertex identity, such as the
// decimator or an indexed reader, so indexed writers need not weld again). Consumers that do
// not understand a channel ignore it.
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <vector>

namespace meshstream::io {

struct Channels {
    bool color = false;      // 3 × uint8 per corner
    bool normal = false;     // 3 × float per corner
    bool vertex_id = false;  // 1 × uint64 per corner; equal ids mean the same vertex
    bool operator==(const Channels&) const = default;
};

class TriangleChunk {
public:
    static constexpr size_t kDefaultCapacity = 16384;  // 576 KiB of positions

    // Throws std::invalid_argument for a capacity of 0 (readers could then never make progress).
    explicit TriangleChunk(size_t capacity = kDefaultCapacity, Channels channels = {})
        : capacity_(capacity), channels_(channels) {
        if (capacity == 0) throw std::invalid_argument("TriangleChunk: capacity must be at least 1");
        xyz_.resize(9 * capacity);
        if (channels.color) rgb_.resize(9 * capacity);
        if (channels.normal) normal_.resize(9 * capacity);
        if (channels.vertex_id) id_.resize(3 * capacity);
    }

    size_t size() const { return size_; }
    size_t capacity() const { return capacity_; }
    bool empty() const { return size_ == 0; }
    bool full() const { return size_ == capacity_; }
    void clear() { size_ = 0; }
    const Channels& channels() const { return channels_; }

    // Re-shapes the chunk for other channels (reallocates only when a channel is added).
    void set_channels(Channels channels) {
        channels_ = channels;
        if (channels.color) rgb_.resize(9 * capacity_);
        if (channels.normal) normal_.resize(9 * capacity_);
        if (channels.vertex_id) id_.resize(3 * capacity_);
    }

    std::span<const float> xyz() const { return {xyz_.data(), 9 * size_}; }
    std::span<float> xyz() { return {xyz_.data(), 9 * size_}; }
    std::span<const uint8_t> rgb() const { return {rgb_.data(), channels_.color ? 9 * size_ : 0}; }
    std::span<uint8_t> rgb() { return {rgb_.data(), channels_.color ? 9 * size_ : 0}; }
    std::span<const float> normals() const { return {normal_.data(), channels_.normal ? 9 * size_ : 0}; }
    std::span<float> normals() { return {normal_.data(), channels_.normal ? 9 * size_ : 0}; }
    std::span<const uint64_t> vertex_ids() const { return {id_.data(), channels_.vertex_id ? 3 * size_ : 0}; }
    std::span<uint64_t> vertex_ids() { return {id_.data(), channels_.vertex_id ? 3 * size_ : 0}; }

    // Appends one triangle (positions only; channel slots of the new triangle are zeroed).
    // Throws std::length_error when full().
    void push(const float (&tri)[9]) { std::memcpy(push_slot(), tri, sizeof tri); }

    // Appends one triangle and returns its 9 position floats to fill in place. Channel slots
    // of the new triangle are zeroed. Throws std::length_error when full().
    float* push_slot() {
        if (full()) throw std::length_error("TriangleChunk: push into a full chunk");
        size_t i = size_++;
        if (channels_.color) std::memset(&rgb_[9 * i], 0, 9);
        if (channels_.normal) std::memset(&normal_[9 * i], 0, 9 * sizeof(float));
        if (channels_.vertex_id) std::memset(&id_[3 * i], 0, 3 * sizeof(uint64_t));
        return &xyz_[9 * i];
    }

    // Raw pointers to slot i's channels (i < size()); null when the channel is absent.
    uint8_t* rgb_at(size_t i) { return channels_.color ? &rgb_[9 * i] : nullptr; }
    float* normal_at(size_t i) { return channels_.normal ? &normal_[9 * i] : nullptr; }
    uint64_t* id_at(size_t i) { return channels_.vertex_id ? &id_[3 * i] : nullptr; }

    // Sets size directly after filling xyz storage in bulk (n <= capacity()).
    void resize(size_t n) { assert(n <= capacity_); size_ = n; }
    float* xyz_storage() { return xyz_.data(); }

private:
    size_t capacity_;
    size_t size_ = 0;
    Channels channels_;
    std::vector<float> xyz_;
    std::vector<uint8_t> rgb_;
    std::vector<float> normal_;
    std::vector<uint64_t> id_;
};

}  // namespace meshstream::io
