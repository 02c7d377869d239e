// libFuzzer target: the glTF reader (GLB and JSON share one reader, kGltfFormat) on arbitrary
// bytes. The name sits in a directory that does not exist, so a document's external buffer
// URIs resolve to nothing instead of whatever files lie around the fuzzer's working directory.
#include "io/gltf.hpp"
#include "tests/fuzz/fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    meshstream::fuzz::read_all(meshstream::io::kGltfFormat, data, size, "/nonexistent-meshstream-fuzz/fuzz.gltf");
    return 0;
}
