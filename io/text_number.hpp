// Number formatting for the text writers (PLY ascii, OBJ): std::to_chars, so no locale and no
// iostreams, and floats come out in their shortest round-trip form.
#pragma once

#include <charconv>
#include <string>

namespace meshstream::io {

// Appends `v` (an integer or floating-point value) to `out` in std::to_chars' default form:
// decimal integers, shortest round-trip floats. Allocates only when `out` grows.
template <class N>
void append_number(std::string& out, N v) {
    char buf[32];
    out.append(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);  // shortest round-trip form
}

}  // namespace meshstream::io
