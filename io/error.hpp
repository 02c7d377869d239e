// The one error type of meshstream's I/O: every reader, writer and byte stream throws
// io::Error, carrying the file, the position (byte offset and/or line) and a message, so the
// CLI can print a compiler-style diagnostic ("scan.stl:1207: expected 'endloop', found ...").
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "io/shim_option_error.hpp"

namespace meshstream::io {

class Error : public std::runtime_error {
public:
    static constexpr uint64_t kNoOffset = ~uint64_t{0};

    // `line` is 1-based (0 = not known); `byte_offset` is kNoOffset when not known.
    Error(std::string file, uint64_t byte_offset, uint64_t line, std::string message);
    // An error about a file as a whole (no position).
    Error(std::string file, std::string message);

    const std::string& file() const { return file_; }
    uint64_t byte_offset() const { return byte_offset_; }
    uint64_t line() const { return line_; }
    const std::string& message() const { return message_; }

private:
    std::string file_;
    uint64_t byte_offset_;
    uint64_t line_;
    std::string message_;
};

// Text from a file (or a library quoting one) for an error message, on one line: printable
// ASCII as it is, anything else (newlines too) as \xNN, cut with "..." after `max_chars`.
std::string printable(std::string_view text, size_t max_chars);

// Formats a (possibly binary) token for an error message: printable(token, 32), quoted.
std::string quote_token(std::string_view token);

}  // namespace meshstream::io
