// Wavefront MTL, the material library beside an OBJ: read into io::Material (name, Kd as the
// base colour, d or Tr as its alpha, map_Kd as its texture with the image's bytes) and written
// back from them. MTL files are small and read whole; the texture images they name are held
// whole in memory, within an image budget (past it an image is kept by its name only). Every
// other statement (Ka, Ks, Ns, illum, map_Bump, ...) is skipped and named in MtlFindings, so
// the reader can say what a material lost.
#pragma once

#include "io/format.hpp"

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace meshstream::io {

// What reading MTL files found that the user should hear of; each list in the order met,
// without repeats.
struct MtlFindings {
    std::vector<std::string> missing_images;    // texture paths looked for and not found
    std::vector<std::string> unloaded_images;   // found, but past the image budget: kept by name
    std::vector<std::string> skipped_keywords;  // statements not kept: "Ka", "Ks", "map_Bump", ...
    std::vector<std::string> redefined;         // material names defined again (the first kept)
    std::vector<std::string> images_read;       // texture files read (MeshHeader::side_files)
};

// Reads the MTL file at `path` and returns its materials in file order (a name defined twice
// in it: the first definition, the name added to findings.redefined). Statements: `newmtl
// name` (the rest of the line), `Kd r g b` (one number: grey), `d alpha` (`d -halo a` too),
// `Tr t` (alpha 1 - t, unless the material has `d`), `map_Kd [options] file`; lines end in LF
// or CRLF, `#` starts a comment, `\` continues a line. A texture is read from the MTL's
// directory (a path with `\` separators is tried with `/` too) while `*image_budget_bytes`
// holds it, which it then shrinks; its uri is `uri_dir` (the MTL's directory as the OBJ named
// it, with a trailing '/', or empty) followed by the name in the MTL, or the absolute path.
// Throws io::Error naming the file and line for a statement it cannot read (a bad number, a
// property before any newmtl, a map_Kd without a file name, bytes that are not text), or when
// the file cannot be read; a file over 16 MiB is refused as not an MTL file.
std::vector<Material> read_mtl(const std::string& path, const std::string& uri_dir, uint64_t* image_budget_bytes,
                               MtlFindings& findings);

// The MTL text for `materials` under the names `names` (one per material: unique, one line
// each), with `texture_files[i]` as material i's map_Kd (empty: none): newmtl, Kd, d when the
// alpha is not 1, map_Kd. Numbers in their shortest round-trip form.
std::string write_mtl(std::span<const Material> materials, std::span<const std::string> names,
                      std::span<const std::string> texture_files);

// "image/png" or "image/jpeg" by the bytes' magic, else by the name's extension (png, jpg,
// jpeg), else empty.
std::string image_mime_type(std::span<const std::byte> bytes, std::string_view name);

}  // namespace meshstream::io
