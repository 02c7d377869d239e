// The line reader of the line-structured text formats: OBJ and MTL statements and the PLY
// header. It hands out one line at a time from a ByteSource, without its newline and trailing
// blanks (' ', '\t', '\r', '\v', '\f', so CRLF files read as LF ones), optionally joining a line
// that ends in a backslash with the next (OBJ and MTL continuation lines, joined with a space),
// and knows where each line began (1-based physical line number and byte offset) for errors.
// Token-structured text (ASCII STL, a PLY's ASCII body) is tokenized by its reader instead: line
// breaks mean nothing there.
//
// Errors (io::Error naming the source, the line and its offset): a line longer than the
// source's buffer (ByteSource::kBufferBytes, 1 MiB); a carriage return inside a line, which is
// how a file with CR-only line ends (classic Mac OS) would otherwise read as one long line.
// Memory: a joined line's bytes; a plain line is a view of the source's buffer.
#pragma once

#include "io/byte_stream.hpp"

#include <cstdint>
#include <string>
#include <string_view>

namespace meshstream::io {

class LineReader {
public:
    // `what` names a line in the too-long error ("line", "header line").
    LineReader(ByteSource& source, bool join_continuations, std::string_view what = "line")
        : source_(source), join_(join_continuations), what_(what) {}

    // The next line in `line` (valid until the next call), or false at the end of the input.
    bool next(std::string_view& line);

    // Where the line last returned began: its physical line number (1-based) and byte offset.
    uint64_t line_number() const { return line_number_; }
    uint64_t line_offset() const { return line_offset_; }
    // Physical lines consumed so far (the next line is number physical_lines() + 1).
    uint64_t physical_lines() const { return physical_lines_; }
    // True when the last physical line read had text but no '\n' (the input ends without one).
    bool unterminated() const { return unterminated_; }

private:
    ByteSource& source_;
    bool join_;
    std::string_view what_;
    std::string joined_;
    uint64_t line_number_ = 0, line_offset_ = 0, physical_lines_ = 0;
    bool unterminated_ = false;
};

// The error text for a carriage return inside a line.
extern const char* const kCarriageReturnInLine;

}  // namespace meshstream::io
