// libFuzzer target: the obj reader (kObjFormat) on arbitrary bytes, via fuzz_input.hpp.
#include "io/obj.hpp"
#include "tests/fuzz/fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    meshstream::fuzz::read_all(meshstream::io::kObjFormat, data, size, "fuzz.obj");
    return 0;
}
