// MTL reading and writing (see mtl.hpp): the file is read whole and parsed line by line, as
// the OBJ reader does its statements, words and numbers in the text grammar of
// io/text_tokens.hpp.
#include "io/mtl.hpp"

#include "io/byte_stream.hpp"
#include "io/error.hpp"
#include "io/line_reader.hpp"
#include "io/text_number.hpp"
#include "io/text_tokens.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>

namespace meshstream::io {
namespace {

constexpr uint64_t kMaxMtlBytes = uint64_t{16} << 20;

void add_once(std::vector<std::string>& list, std::string item) {
    if (std::find(list.begin(), list.end(), item) == list.end()) list.push_back(std::move(item));
}

// The whole file, refused past kMaxMtlBytes or when it is not text.
// The bytes of a regular file, or false when it does not exist or is not a regular file.
// Throws io::Error when it exists but cannot be read.
bool read_image(const std::string& path, uint64_t* budget, std::vector<std::byte>& bytes, bool* over_budget) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        if (errno == ENOENT || errno == ENOTDIR) return false;
        throw Error(path, "cannot open the texture image: " + std::string(std::strerror(errno)));
    }
    struct stat st;
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        return false;
    }
    const uint64_t size = static_cast<uint64_t>(st.st_size);
    if (size > *budget) {
        ::close(fd);
        *over_budget = true;
        return true;
    }
    bytes.resize(static_cast<size_t>(size));
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t got = ::read(fd, bytes.data() + done, bytes.size() - done);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) {
            const std::string why = got < 0 ? std::strerror(errno) : "it ended early";
            ::close(fd);
            throw Error(path, "cannot read the texture image: " + why);
        }
        done += static_cast<size_t>(got);
    }
    ::close(fd);
    *budget -= size;
    return true;
}

// map_Kd's options and how many arguments each takes (-o, -s, -t: up to three numbers).
int option_arguments(std::string_view option) {
    static constexpr std::pair<std::string_view, int> kOptions[] = {
        {"-blendu", 1},  {"-blendv", 1}, {"-boost", 1}, {"-mm", 2},         {"-texres", 1}, {"-clamp", 1}, {"-bm", 1},
        {"-imfchan", 1}, {"-type", 1},   {"-cc", 1},    {"-colorspace", 1}, {"-o", -3},     {"-s", -3},    {"-t", -3},
    };
    for (const auto& [name, n] : kOptions)
        if (option == name) return n;
    return 0;
}

class MtlParser {
public:
    MtlParser(const std::string& path, const std::string& uri_dir, uint64_t* image_budget, MtlFindings& findings)
        : path_(path), uri_dir_(uri_dir), dir_(parent_dir(path)), budget_(image_budget), findings_(findings) {}

    // Reads statements until the end of `source`: one logical line each (io::LineReader:
    // continuation lines joined). Throws io::Error naming the line.
    std::vector<Material> parse(ByteSource& source) {
        LineReader lines(source, /*join_continuations=*/true);
        std::string_view line;
        while (lines.next(line)) {
            line_ = lines.line_number();
            if (source.offset() > kMaxMtlBytes)
                throw Error(path_, "larger than " + binary_size(kMaxMtlBytes) + ": not an MTL file");
            for (char c : line) {
                const auto u = static_cast<unsigned char>(c);
                if (u < 0x20 && c != '\t' && c != '\v' && c != '\f')
                    fail("is not text (a byte " + std::to_string(u) + " in it): not an MTL file");
            }
            statement(trim_blanks(line));
        }
        finish_material();
        return std::move(materials_);
    }

private:
    [[noreturn]] void fail(const std::string& message) const { throw Error(path_, Error::kNoOffset, line_, message); }

    float number(std::string_view tok, const char* what) const {
        float v = 0;
        if (tok.empty()) fail(std::string("expected ") + what + ", found the end of the line");
        if (!parse_number(tok, v)) fail(std::string("expected ") + what + ", found " + quote_token(tok));
        return v;
    }

    void statement(std::string_view line) {
        std::string_view rest = line;
        std::string_view key = next_word(rest);
        if (key.empty() || key[0] == '#') return;
        if (!std::all_of(key.begin(), key.end(), [](char c) {
                return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
            }))
            fail("not an MTL statement: " + quote_token(key));
        if (key == "newmtl") {
            finish_material();
            std::string_view name = trim_blanks(rest);
            if (name.empty()) fail("'newmtl' without a material name");
            current_ = Material{};
            current_.name = std::string(name);
            has_current_ = true;
            has_d_ = false;
            return;
        }
        if (key != "Kd" && key != "d" && key != "Tr" && key != "map_Kd") {
            add_once(findings_.skipped_keywords, std::string(key));
            return;
        }
        if (!has_current_) fail("'" + std::string(key) + "' before any 'newmtl'");
        if (key == "map_Kd") {
            texture(rest);
            return;
        }
        rest = rest.substr(0, rest.find('#'));  // a comment may end a number statement
        if (key == "Kd") {
            std::string_view first = next_word(rest);
            if (first == "spectral" || first == "xyz") {  // other colour spaces: not kept
                add_once(findings_.skipped_keywords, "Kd " + std::string(first));
                return;
            }
            float rgb[3];
            rgb[0] = number(first, "a colour component after 'Kd'");
            std::string_view g = next_word(rest);
            if (g.empty()) {
                rgb[1] = rgb[2] = rgb[0];  // one number: grey
            } else {
                rgb[1] = number(g, "a colour component after 'Kd'");
                rgb[2] = number(next_word(rest), "a colour component after 'Kd'");
            }
            if (!next_word(rest).empty()) fail("'Kd' with more than 3 numbers");
            std::copy(rgb, rgb + 3, current_.base_color.begin());
            return;
        }
        std::string_view tok = next_word(rest);
        if (key == "d" && tok == "-halo") tok = next_word(rest);
        const float v = number(tok, key == "d" ? "an alpha after 'd'" : "a transparency after 'Tr'");
        if (!next_word(rest).empty()) fail("'" + std::string(key) + "' with more than one number");
        if (key == "d") {
            current_.base_color[3] = v;
            has_d_ = true;
        } else if (!has_d_) {
            current_.base_color[3] = 1.0f - v;
        }
    }

    void texture(std::string_view rest) {
        // Options first ("-s 1 1 1", "-clamp on"), then the file name, which may hold spaces.
        for (;;) {
            std::string_view probe = rest;
            std::string_view word = next_word(probe);
            if (word.size() < 2 || word[0] != '-') break;
            const int n = option_arguments(word);
            if (n == 0) break;  // not an option we know: part of the name
            rest = probe;
            for (int k = 0; k < (n < 0 ? -n : n); ++k) {
                std::string_view after = rest;
                std::string_view arg = next_word(after);
                float ignored;
                if (arg.empty() || (n < 0 && !parse_number(arg, ignored))) break;
                rest = after;
            }
        }
        const std::string name(trim_blanks(rest));
        if (name.empty()) fail("'map_Kd' without a file name");
        Texture t;
        const bool absolute = name[0] == '/';
        std::string found = absolute ? name : dir_ + "/" + name;
        std::string uri = absolute ? name : uri_dir_ + name;
        bool over_budget = false;
        bool exists = read_image(found, budget_, t.bytes, &over_budget);
        if (!exists && name.find('\\') != std::string::npos) {  // written on Windows
            std::string slashed = name;
            std::replace(slashed.begin(), slashed.end(), '\\', '/');
            const std::string again = slashed[0] == '/' ? slashed : dir_ + "/" + slashed;
            if ((exists = read_image(again, budget_, t.bytes, &over_budget))) {
                found = again;
                uri = slashed[0] == '/' ? slashed : uri_dir_ + slashed;
            }
        }
        if (!exists) add_once(findings_.missing_images, found);
        if (over_budget) add_once(findings_.unloaded_images, found);
        if (exists && !over_budget) add_once(findings_.images_read, found);
        t.uri = uri;
        t.mime_type = image_mime_type(t.bytes, name);
        current_.texture = std::move(t);
    }

    void finish_material() {
        if (!has_current_) return;
        has_current_ = false;
        for (const Material& m : materials_)
            if (m.name == current_.name) {
                add_once(findings_.redefined, current_.name);
                return;
            }
        materials_.push_back(std::move(current_));
    }

    const std::string& path_;
    const std::string& uri_dir_;
    std::string dir_;
    uint64_t* budget_;
    MtlFindings& findings_;
    uint64_t line_ = 0;
    std::vector<Material> materials_;
    Material current_;
    bool has_current_ = false, has_d_ = false;
};

}  // namespace

std::vector<Material> read_mtl(const std::string& path, const std::string& uri_dir, uint64_t* image_budget_bytes,
                               MtlFindings& findings) {
    std::unique_ptr<ByteSource> source = ByteSource::open(path);
    return MtlParser(path, uri_dir, image_budget_bytes, findings).parse(*source);
}

std::string write_mtl(std::span<const Material> materials, std::span<const std::string> names,
                      std::span<const std::string> texture_files) {
    std::string out = "# generated by meshstream\n";
    for (size_t i = 0; i < materials.size(); ++i) {
        const Material& m = materials[i];
        out += "\nnewmtl " + names[i] + "\nKd";
        for (int a = 0; a < 3; ++a) {
            out += ' ';
            append_number(out, m.base_color[a]);
        }
        out += '\n';
        if (m.base_color[3] != 1.0f) {
            out += "d ";
            append_number(out, m.base_color[3]);
            out += '\n';
        }
        if (!texture_files[i].empty()) out += "map_Kd " + texture_files[i] + "\n";
    }
    return out;
}

std::string image_mime_type(std::span<const std::byte> bytes, std::string_view name) {
    auto starts = [&](std::string_view magic) {
        return bytes.size() >= magic.size() && std::memcmp(bytes.data(), magic.data(), magic.size()) == 0;
    };
    if (starts("\x89PNG\r\n\x1a\n")) return "image/png";
    if (starts("\xFF\xD8\xFF")) return "image/jpeg";
    std::string ext(
        name.substr(name.find_last_of('.') == std::string_view::npos ? name.size() : name.find_last_of('.') + 1));
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == "png") return "image/png";
    if (ext == "jpg" || ext == "jpeg") return "image/jpeg";
    return {};
}

}  // namespace meshstream::io
