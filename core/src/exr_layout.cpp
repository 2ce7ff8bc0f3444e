#include "exr_layout.h"

#include <haze/core/error.h>

#include <cstdint>
#include <fstream>
#include <map>

namespace haze {

namespace {

constexpr std::uint32_t kMagic = 20000630;    // the first 4 bytes, little-endian as all of them
constexpr std::uint32_t kMultiPart = 0x1000;  // a flag of the version, the next 4
constexpr std::size_t kLongestName = 255;     // with the long-names flag; 31 without

struct Reader {
  std::ifstream in;
  std::uint64_t size = 0;
  const std::string& field;

  std::uint64_t at() { return static_cast<std::uint64_t>(in.tellg()); }
  [[noreturn]] void short_file() {
    throw Error(field, "a header that ends at byte " + to_text(size) + ", the file's end", "a complete OpenEXR header");
  }
  // A null-terminated name or type; "" at a header's end.
  std::string text(const char* what) {
    std::string s;
    for (char c; in.get(c) && c != '\0';) {
      if (s.size() == kLongestName) throw Error(field, std::string("a ") + what + " longer than 255 bytes", "an OpenEXR header");
      s += c;
    }
    if (!in) short_file();
    return s;
  }
  std::int32_t int32() {
    unsigned char b[4];
    if (!in.read(reinterpret_cast<char*>(b), 4)) short_file();
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
                                     static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24);
  }
};

// Scan lines per chunk, by compression (ImfCompression.h's order).
long long lines_per_chunk(int compression) {
  switch (compression) {
    case 3: case 5: return 16;          // ZIP, PXR24
    case 4: case 6: case 7: case 8: return 32;  // PIZ, B44, B44A, DWAA
    case 9: return 256;                  // DWAB
    default: return 1;                   // NONE, RLE, ZIPS (others OpenEXR refuses)
  }
}

// Bytes that OpenEXR 3.1 reads for a value of a fixed-size type, whatever size the header states
// (ImfStandardAttributes.h's types); 0 for others.
int fixed_size(const std::string& type) {
  static const std::map<std::string, int> sizes = {
      {"box2i", 16}, {"box2f", 16}, {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1}, {"double", 8},
      {"envmap", 1}, {"float", 4}, {"int", 4}, {"keycode", 28}, {"lineOrder", 1}, {"m33f", 36}, {"m33d", 72},
      {"m44f", 64}, {"m44d", 128}, {"rational", 8}, {"tiledesc", 9}, {"timecode", 8}, {"v2i", 8}, {"v2f", 8},
      {"v2d", 16}, {"v3i", 12}, {"v3f", 12}, {"v3d", 24}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? 0 : it->second;
}

// The value of an attribute of `size` bytes, read as OpenEXR reads it (which follows a value's
// own counts, not `size`, for channel lists, previews and string vectors): it must end where
// `size` says, so that the walk and OpenEXR stay in step.
void skip_value(Reader& r, const std::string& name, const std::string& type, std::int32_t size) {
  const std::uint64_t start = r.at(), end = start + static_cast<std::uint64_t>(size);
  const auto wrong = [&](const std::string& what) {
    throw Error(r.field, "an attribute '" + name + "' of type " + type + " whose value " + what,
                "a value laid out as its type's, " + to_text(size) + " bytes as its header says");
  };
  if (const int fixed = fixed_size(type)) {
    if (size != fixed) wrong("is stated as " + to_text(size) + " bytes where the type has " + to_text(fixed));
  } else if (type == "chlist") {  // name\0 then 16 bytes a channel, ended by an empty name
    while (!r.text("channel name").empty()) {
      r.in.seekg(16, std::ios::cur);
      if (r.at() > end) wrong("runs past its stated size");
    }
    if (r.at() != end) wrong("ends before its stated size");
  } else if (type == "preview") {  // width, height, then 4 bytes a pixel
    const auto width = static_cast<std::uint32_t>(r.int32()), height = static_cast<std::uint32_t>(r.int32());
    if (size < 8 || size % 4 != 0 || static_cast<std::uint64_t>(width) * height != static_cast<std::uint64_t>(size - 8) / 4)
      wrong("holds a " + to_text(width) + " x " + to_text(height) + " preview in " + to_text(size) + " bytes");
  } else if (type == "stringvector") {  // length, then the string, each
    while (r.at() < end) {
      const std::int32_t length = r.int32();
      if (length < 0 || r.at() + static_cast<std::uint64_t>(length) > end) wrong("holds a string of " + to_text(length) + " bytes past its stated size");
      r.in.seekg(length, std::ios::cur);
    }
  }
  r.in.seekg(static_cast<std::streamoff>(end));
}

// One header: its attributes within the file, and its offset table's size within the file.
// Returns false for the empty header that ends a multi-part file's list.
bool check_header(Reader& r, bool first) {
  std::int32_t window[4] = {0, 0, -1, -1};
  int compression = 0;
  std::int32_t tile[2] = {0, 0};
  bool has_window = false, tiled = false;
  for (bool any = false;; any = true) {
    const std::string name = r.text("attribute name");
    if (name.empty()) {
      if (!any && !first) return false;
      break;
    }
    const std::string type = r.text("attribute type");
    const std::int32_t size = r.int32();
    const std::uint64_t left = r.size - r.at();
    if (size < 0 || static_cast<std::uint64_t>(size) > left)
      throw Error(r.field, "an attribute '" + name + "' of " + to_text(size) + " bytes with " + to_text(left) + " left in the file",
                  "an OpenEXR header whose attributes lie within the file");
    if (name == "dataWindow" && type == "box2i" && size == 16) {
      for (auto& v : window) v = r.int32();
      has_window = true;
    } else if (name == "compression" && type == "compression" && size == 1) {
      compression = r.in.get();
    } else if (name == "tiles" && type == "tiledesc" && size == 9) {
      tile[0] = r.int32(), tile[1] = r.int32();
      r.in.ignore(1);
      tiled = true;
    } else {
      skip_value(r, name, type, size);
    }
  }
  if (!has_window) return true;  // OpenEXR refuses a header without one
  const long long w = static_cast<long long>(window[2]) - window[0] + 1, h = static_cast<long long>(window[3]) - window[1] + 1;
  if (w <= 0 || h <= 0) return true;  // OpenEXR refuses it
  // Chunks: scan-line blocks, or at least the tiles of the full-resolution level (each count
  // below 2^33, their product compared by division).
  const long long across = tiled && tile[0] > 0 ? (w + tile[0] - 1) / tile[0] : 1;
  const long long down = tiled && tile[1] > 0 ? (h + tile[1] - 1) / tile[1] : (h + lines_per_chunk(compression) - 1) / lines_per_chunk(compression);
  const long long most = static_cast<long long>(r.size / 8);
  if (across > most || down > most / across)
    throw Error(r.field, "a data window of " + to_text(w) + " x " + to_text(h) + " pixels in " + to_text(across) + " x " + to_text(down) +
                             " chunks, in a file of " + to_text(r.size) + " bytes",
                "a file that holds its chunks' offsets (8 bytes each)");
  return true;
}

}  // namespace

void check_exr_layout(const std::filesystem::path& path, const std::string& field) {
  Reader r{std::ifstream(path, std::ios::binary), 0, field};
  std::error_code ec;
  r.size = std::filesystem::file_size(path, ec);
  if (!r.in || ec) return;  // OpenEXR names what is wrong with the path
  if (r.size < 8 || static_cast<std::uint32_t>(r.int32()) != kMagic) return;
  const bool multi_part = (static_cast<std::uint32_t>(r.int32()) & kMultiPart) != 0;
  if (!check_header(r, true) || !multi_part) return;
  while (check_header(r, false)) {
  }
}

}  // namespace haze
