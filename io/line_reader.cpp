#include "io/line_reader.hpp"

#include "io/error.hpp"
#include "io/text_tokens.hpp"

#include <cstring>

namespace meshstream::io {

const char* const kCarriageReturnInLine =
    "carriage return inside a line: lines ending in CR alone (classic Mac OS) are not supported "
    "(tr '\\r' '\\n' converts them)";

bool LineReader::next(std::string_view& line) {
    joined_.clear();
    bool joining = false;
    for (;;) {
        auto w = source_.window();
        if (w.empty()) {
            if (!joining) return false;
            line = joined_;  // a continuation at the very end: the joined text is the line
            return true;
        }
        const char* p = reinterpret_cast<const char*>(w.data());
        const void* nl = std::memchr(p, '\n', w.size());
        if (!nl && w.size() < ByteSource::kBufferBytes) {  // the line may go on past the window
            w = source_.peek(ByteSource::kBufferBytes);
            p = reinterpret_cast<const char*>(w.data());
            nl = std::memchr(p, '\n', w.size());
        }
        if (!joining) {
            line_offset_ = source_.offset();
            line_number_ = physical_lines_ + 1;
        }
        if (!nl && w.size() >= ByteSource::kBufferBytes) {
            const uint64_t at = source_.offset();
            if (std::memchr(p, '\r', w.size()))
                throw Error(source_.name(), at, physical_lines_ + 1, kCarriageReturnInLine);
            throw Error(source_.name(), at, physical_lines_ + 1,
                        std::string(what_) + " longer than " + std::to_string(ByteSource::kBufferBytes >> 20) + " MiB");
        }
        const size_t len = nl ? static_cast<size_t>(static_cast<const char*>(nl) - p) : w.size();
        std::string_view view(p, len);
        const uint64_t at = source_.offset();
        source_.consume(nl ? len + 1 : len);
        ++physical_lines_;
        while (!view.empty() && is_blank(view.back())) view.remove_suffix(1);
        unterminated_ = !nl && !view.empty();
        if (std::memchr(view.data(), '\r', view.size()))
            throw Error(source_.name(), at, physical_lines_, kCarriageReturnInLine);
        if (join_ && !view.empty() && view.back() == '\\') {
            view.remove_suffix(1);
            joined_.append(view);
            joined_ += ' ';
            joining = true;
            continue;
        }
        if (joining) {
            joined_.append(view);
            line = joined_;
        } else {
            line = view;
        }
        return true;
    }
}

}  // namespace meshstream::io
