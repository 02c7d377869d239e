// libFuzzer target: EXT_meshopt_compression in the glTF reader, libmeshoptimizer's decoders and
// filters and the checks in front of them. The input is the BIN chunk of a fixed GLB whose two
// compressed bufferViews, positions and indices, split it in halves; its first bytes choose the
// positions' stride, type and filter, the index mode and size, and the counts. So every decoder
// and filter is reached at once, without the fuzzer first having to find valid JSON (the whole
// document is fuzz_gltf's job).
#include "io/gltf.hpp"
#include "tests/fuzz/fuzz_input.hpp"

#include <string>

namespace {

void put_u32(std::string& out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 3) return 0;
    const uint8_t select = data[0];
    const unsigned vertices = 1 + data[1], triangles = data[2];
    const char* strides[4] = {"4", "8", "12", "16"};
    const char* types[4] = {"5120", "5122", "5126", "5126"};  // byte, short (quantized), float, float
    const char* filters[4] = {"NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL"};
    const int s = select & 3;
    const unsigned stride = 4 * (s + 1);
    const bool sequence = select & 16, wide = select & 32;
    const std::string bin(reinterpret_cast<const char*>(data) + 3, size - 3);
    const size_t half = bin.size() / 2;
    const unsigned index_bytes = wide ? 4 : 2;
    const std::string json =
        std::string(
            R"({"asset":{"version":"2.0"},"extensionsUsed":["EXT_meshopt_compression","KHR_mesh_quantization"],)") +
        R"("extensionsRequired":["EXT_meshopt_compression","KHR_mesh_quantization"],)" +
        R"("buffers":[{"byteLength":)" + std::to_string(bin.size()) + R"(},{"byteLength":)" +
        std::to_string(vertices * stride + 3 * triangles * index_bytes) +
        R"(,"extensions":{"EXT_meshopt_compression":{"fallback":true}}}],"bufferViews":[)" +
        R"({"buffer":1,"byteLength":)" + std::to_string(vertices * stride) + R"(,"byteStride":)" + strides[s] +
        R"(,"extensions":{"EXT_meshopt_compression":{"buffer":0,"byteLength":)" + std::to_string(half) +
        R"(,"byteStride":)" + strides[s] + R"(,"count":)" + std::to_string(vertices) +
        R"(,"mode":"ATTRIBUTES","filter":")" + filters[(select >> 2) & 3] + R"("}}},)" +
        R"({"buffer":1,"byteOffset":)" + std::to_string(vertices * stride) + R"(,"byteLength":)" +
        std::to_string(3 * triangles * index_bytes) + R"(,"extensions":{"EXT_meshopt_compression":{"buffer":0,)" +
        R"("byteOffset":)" + std::to_string(half) + R"(,"byteLength":)" + std::to_string(bin.size() - half) +
        R"(,"byteStride":)" + std::to_string(index_bytes) + R"(,"count":)" + std::to_string(3 * triangles) +
        R"(,"mode":")" + (sequence ? "INDICES" : "TRIANGLES") + R"("}}}],"accessors":[)" +
        R"({"bufferView":0,"componentType":)" + types[s] + R"(,"normalized":)" +
        (s < 2 && (select & 64) ? "true" : "false") + R"(,"count":)" + std::to_string(vertices) +
        R"(,"type":"VEC3"},)" + R"({"bufferView":1,"componentType":)" + (wide ? "5125" : "5123") + R"(,"count":)" +
        std::to_string(3 * triangles) +
        R"(,"type":"SCALAR"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)" +
        R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
    std::string text = json;
    while (text.size() % 4) text.push_back(' ');
    std::string body = bin;
    while (body.size() % 4) body.push_back('\0');
    std::string glb = "glTF";
    put_u32(glb, 2);
    put_u32(glb, static_cast<uint32_t>(12 + 8 + text.size() + 8 + body.size()));
    put_u32(glb, static_cast<uint32_t>(text.size()));
    glb += "JSON" + text;
    put_u32(glb, static_cast<uint32_t>(body.size()));
    glb += std::string("BIN\0", 4) + body;
    meshstream::fuzz::read_all(meshstream::io::kGlbFormat, reinterpret_cast<const uint8_t*>(glb.data()), glb.size(),
                               "/nonexistent-meshstream-fuzz/fuzz.glb");
    return 0;
}
