// The layout of an OpenEXR file's headers, checked before OpenEXR reads them.
#pragma once

#include <filesystem>
#include <string>

namespace haze {

// Walks every header of the file at `path` (OpenEXR's "Technical Introduction", "File Layout":
// magic and version, then attributes name\0 type\0 size value, ended by an empty name; a
// multi-part file's headers follow one another, ended by an empty header) and throws a
// haze::Error naming `field` where an attribute's size runs past the file's end or a part's
// chunk offset table (8 bytes a chunk, counted from its data window) cannot fit in the file.
// OpenEXR 3.1 allocates, and for strings fills, whatever size a header gives, and allocates the
// offset table for any window: a file of 300 bytes may claim 2 GB. A file that is not OpenEXR is
// left to OpenEXR's own error.
void check_exr_layout(const std::filesystem::path& path, const std::string& field);

}  // namespace haze
