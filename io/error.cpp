// io::Error: formats what() like a compiler diagnostic.
#include "io/error.hpp"

#include <cstdio>

namespace meshstream::io {
namespace {

std::string format_what(const std::string& file, uint64_t byte_offset, uint64_t line, const std::string& message) {
    std::string out = file.empty() ? std::string("<input>") : file;
    // Appended piece by piece: `"literal" + std::string` trips GCC 12's -Wrestrict here.
    if (line != 0) {
        out += ':';
        out += std::to_string(line);
    }
    if (byte_offset != Error::kNoOffset) {
        out += ": byte ";
        out += std::to_string(byte_offset);
    }
    out += ": ";
    out += message;
    return out;
}

}  // namespace

Error::Error(std::string file, uint64_t byte_offset, uint64_t line, std::string message)
    : std::runtime_error(format_what(file, byte_offset, line, message)),
      file_(std::move(file)),
      byte_offset_(byte_offset),
      line_(line),
      message_(std::move(message)) {}

Error::Error(std::string file, std::string message) : Error(std::move(file), kNoOffset, 0, std::move(message)) {}

std::string printable(std::string_view text, size_t max_chars) {
    std::string out;
    size_t n = 0;
    for (char c : text) {
        if (++n > max_chars) {
            out += "...";
            break;
        }
        unsigned char u = static_cast<unsigned char>(c);
        if (u >= 0x20 && u < 0x7f) {
            out += c;
        } else {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02x", u);
            out += buf;
        }
    }
    return out;
}

std::string quote_token(std::string_view token) {
    std::string out = "'";  // piece by piece, as in format_what: GCC 12's -Wrestrict
    out += printable(token, 32);
    out += '\'';
    return out;
}

}  // namespace meshstream::io
