// glTF's format descriptors and content probes; the reader and writer live in
// io/gltf_reader.cpp and io/gltf_writer.cpp.
#include "io/gltf.hpp"
#include "io/gltf_internal.hpp"

#include <cstring>
#include <string_view>

namespace meshstream::io {

using gltf_detail::kGlbMagic;

const Format kGlbFormat = {
    "glb",
    "glb",
    "binary glTF 2.0 (Draco by default; whole mesh in memory)",
    &probe_glb,
    &gltf_detail::open_gltf_reader,
    &gltf_detail::open_glb_writer,
    Format::kDracoUnlessOff | Format::kWholeMesh,
    nullptr,
    &gltf_detail::gltf_keep_channels,
};

const Format kGltfFormat = {
    "gltf",
    "gltf",
    "glTF 2.0 JSON + .bin (Draco by default; whole mesh in memory)",
    &probe_gltf_json,
    &gltf_detail::open_gltf_reader,
    &gltf_detail::open_gltf_writer,
    Format::kDracoUnlessOff | Format::kWholeMesh,
    nullptr,
    &gltf_detail::gltf_keep_channels,
    &gltf_detail::gltf_side_files,
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
