// Test helpers over the format registry, so tests that cover "every format" follow
// io::formats() and a new format is covered by registering it.
#pragma once

#include "io/format.hpp"

#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

namespace meshstream::test {

// The extension a file of format f is named with: its first one, or for a variant without
// extensions of its own ("ply-ascii") that of the format it is a variant of ("ply").
inline std::string file_extension(const io::Format& f) {
    std::string_view exts = f.extensions;
    if (exts.empty()) exts = io::find_format(f.name.substr(0, f.name.find('-')))->extensions;
    return std::string(exts.substr(0, exts.find(' ')));
}

// The extension of every readable format, once each ("stl" for both STL formats).
inline std::vector<std::string> readable_extensions() {
    std::vector<std::string> exts;
    for (const io::Format* f : io::formats()) {
        if (f->open_reader == nullptr) continue;
        const std::string ext = file_extension(*f);
        if (std::find(exts.begin(), exts.end(), ext) == exts.end()) exts.push_back(ext);
    }
    return exts;
}

}  // namespace meshstream::test
