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
    : meshstream::Error(format_what(file, byte_offset, line, render(message)),
                        format_what(file, byte_offset, line, message)),
      file_(std::move(file)),
      byte_offset_(byte_offset),
      line_(line),
      message_(std::move(message)) {}

Error::Error(std::string file, std::string message) : Error(std::move(file), kNoOffset, 0, std::move(message)) {}

std::string Error::describe(SettingNames name) const {
    return format_what(file_, byte_offset_, line_, render(message_, name));
}

std::string Error::raw_what() const { return format_what(file_, byte_offset_, line_, message_); }

std::string_view setting_words(Setting setting) {
    static constexpr std::string_view kWords[kSettingCount] = {
        "the input",
        "the output",
        "the input format",
        "the output format",
        "the memory budget",
        "the temporary-directory setting",
        "strict mode",
        "the channels left out",
        "dropping bad triangles",
        "the glTF compression",
        "the Draco position bits",
        "the Draco normal bits",
        "the Draco texture coordinate bits",
        "the Draco colour bits",
        "the Draco compression level",
        "the gzip level",
        "the ratio",
        "the target",
        "the buffer",
        "the weld",
        "attribute weights",
        "the sorted axis",
        "the seed",
        "the thread count",
        "the sort policy",
        "the sort axis",
        "the part",
        "the part files",
        "the attributes compared",
        "the output chunk size",
        "the tile triangle budget",
        "the origin",
        "the overwrite setting",
    };
    const int i = int(setting);
    return i >= 0 && i < kSettingCount ? kWords[i] : std::string_view("a setting");
}

namespace {
// A mention: this byte, the setting's number as one byte (1-based, so never a NUL), this byte.
constexpr char kMark = '\x1e';
}  // namespace

std::string mention(Setting setting) { return {kMark, char(int(setting) + 1), kMark}; }

std::string render(std::string_view text, SettingNames name) {
    std::string out;
    out.reserve(text.size());
    for (size_t i = 0; i < text.size(); ++i) {
        if (text[i] == kMark && i + 2 < text.size() && text[i + 2] == kMark) {
            const auto setting = Setting(int(static_cast<unsigned char>(text[i + 1])) - 1);
            out += name != nullptr ? name(setting) : std::string(setting_words(setting));
            i += 2;
        } else {
            out += text[i];
        }
    }
    return out;
}

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

namespace meshstream {

Error::Error(std::string message) : Error(io::render(message), message) {}

}  // namespace meshstream
