// Internals shared by the glTF reader (io/gltf_reader.cpp), writer (io/gltf_writer.cpp) and
// the format descriptors (io/gltf.cpp): GLB framing constants, the extension names, and the
// reader and writer factories. Internal: not part of the library's API.
#pragma once

#include "io/format.hpp"
#include "io/gltf.hpp"

#include <cstdint>
#include <memory>
#include <string>

namespace meshstream::io::gltf_detail {

constexpr char kGlbMagic[4] = {'g', 'l', 'T', 'F'};
constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"
constexpr const char* kDracoExtension = "KHR_draco_mesh_compression";
constexpr const char* kQuantizationExtension = "KHR_mesh_quantization";
constexpr const char* kMeshoptExtension = "EXT_meshopt_compression";

// Little-endian 32-bit fields of the GLB header and chunk headers.
inline void put_u32(std::string& out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
inline uint32_t get_u32(const unsigned char* p) {
    return uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 | uint32_t{p[3]} << 24;
}

// io/gltf_reader.cpp: GLB and JSON glTF alike (the content tells them apart).
std::unique_ptr<Reader> open_gltf_reader(ByteSource& source, const ReadOptions& options);
// io/gltf_writer.cpp.
std::unique_ptr<Writer> open_glb_writer(ByteSink& sink, const WriteOptions& options);
std::unique_ptr<Writer> open_gltf_writer(ByteSink& sink, const WriteOptions& options);
// The files a .gltf output at `path` writes beside it: its .bin and its materials' texture
// images (none when written in place).
std::vector<std::string> gltf_side_files(const std::string& path, const WriteOptions& options);
// The compression a glTF writer uses with `options`: GltfSettings's, except that Draco's is
// none in a build without Draco.
GltfSettings::Compression writer_compression(const WriteOptions& options);
// The channels a glTF writer keeps (the same with every --compress).
Channels gltf_keep_channels(const Channels& in, const WriteOptions& options);

}  // namespace meshstream::io::gltf_detail
