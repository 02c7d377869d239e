// glTF's format descriptors and content probes; the reader and writer live in
// io/gltf_reader.cpp and io/gltf_writer.cpp.
#include "io/gltf.hpp"
#include "io/draco.hpp"
#include "io/gltf_internal.hpp"

#include <cstring>
#include <string_view>

namespace meshstream::io {

using gltf_detail::kGlbMagic;

namespace {

// Draco's connectivity coder puts the triangles in an order of its own; meshopt's vertex cache
// order is not applied to a sorted stream.
std::string gltf_reorders_triangles(const WriteOptions& options) {
    return gltf_detail::writer_compression(options) == GltfSettings::Compression::kDraco
               ? "Draco compression reorders triangles"
               : "";
}

bool gltf_takes_options(const std::type_info& type, const WriteOptions& options) {
    return type == typeid(GltfSettings) || (type == typeid(DracoSettings) && gltf_detail::writer_compression(options) ==
                                                                                 GltfSettings::Compression::kDraco);
}

constexpr std::string_view kNoSortedAxis = "glTF has no place for the sorted axis";

}  // namespace

const Format kGlbFormat = {
    .name = "glb",
    .extensions = "glb",
    .description = "binary glTF 2.0 (Draco by default; whole mesh in memory)",
    .probe = &probe_glb,
    .open_reader = &gltf_detail::open_gltf_reader,
    .open_writer = &gltf_detail::open_glb_writer,
    .traits = Format::kWholeMesh,
    .keep_channels = &gltf_detail::gltf_keep_channels,
    .reorders_triangles = &gltf_reorders_triangles,
    .sorted_axis_unrecorded = kNoSortedAxis,
    .takes_options = &gltf_takes_options,
};

const Format kGltfFormat = {
    .name = "gltf",
    .extensions = "gltf",
    .description = "glTF 2.0 JSON + .bin (Draco by default; whole mesh in memory)",
    .probe = &probe_gltf_json,
    .open_reader = &gltf_detail::open_gltf_reader,
    .open_writer = &gltf_detail::open_gltf_writer,
    .traits = Format::kWholeMesh,
    .keep_channels = &gltf_detail::gltf_keep_channels,
    .side_files = &gltf_detail::gltf_side_files,
    .reorders_triangles = &gltf_reorders_triangles,
    .sorted_axis_unrecorded = kNoSortedAxis,
    .takes_options = &gltf_takes_options,
};

bool probe_glb(std::span<const std::byte> head, std::optional<uint64_t>) {
    return head.size() >= 12 && std::memcmp(head.data(), kGlbMagic, 4) == 0;
}

bool probe_gltf_json(std::span<const std::byte> head, std::optional<uint64_t>) {
    std::string_view text(reinterpret_cast<const char*>(head.data()), head.size());
    size_t first = text.find_first_not_of(" \t\r\n");
    if (first == std::string_view::npos || text[first] != '{') return false;
    return text.find("\"asset\"") != std::string_view::npos;
}

}  // namespace meshstream::io
