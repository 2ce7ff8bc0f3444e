// read_openvdb_grid: an OpenVDB file's layout walked and checked (the format as OpenVDB 10 reads
// it: io/Archive.cc readHeader, MetaMap::readMeta, GridDescriptor::read, Archive::writeGrid's
// offsets), then the one grid read by OpenVDB from memory.
#include "checked_read.h"

#include <openvdb/io/DelayedLoadMetadata.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/io/Stream.h>
#include <openvdb/math/Maps.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <limits>

namespace haze::vdb {
namespace {

// DelayedLoadMetadata::readValue: uint32 count, then a mask of count bytes and count int64 sizes,
// each either raw or Blosc-compressed behind a uint32 byte count (the sizes absent when theirs is
// 0xffffffff), then whatever else `size` holds. Both arrays are zero-filled to count entries
// first, so count is held to the file's size (a grid has fewer leaves than its file has bytes).
void delayed_load(Walk& walk, uint32_t size) {
  if (size == 0) return;
  const size_t start = walk.pos;
  const auto count = walk.get<uint32_t>("a delayed-load count");
  if (count > walk.size()) walk.refuse("a VDB file whose delayed-load metadata at byte " + std::to_string(start) + " counts at most one leaf per byte");
  const auto mask = walk.get<uint32_t>("a delayed-load mask");
  walk.skip(mask > 0 ? mask : count, "a delayed-load mask");
  const auto sizes = walk.get<uint32_t>("delayed-load sizes");
  if (sizes != std::numeric_limits<uint32_t>::max()) walk.skip(sizes > 0 ? uint64_t{sizes} : uint64_t{8} * count, "delayed-load sizes");
  if (walk.pos - start < size) walk.skip(size - (walk.pos - start), "a delayed-load value's tail");
}

// MetaMap::readMeta: a count, then per item its name, type name, uint32 size and value; each
// value is passed over as OpenVDB reads it.
void metadata(Walk& walk) {
  const auto count = walk.get<uint32_t>("a metadata count");
  for (uint32_t i = 0; i < count; ++i) {
    walk.string("a metadata name");
    const std::string type = walk.string("a metadata type name");
    const auto size = walk.get<uint32_t>("a metadata value");
    walk.need(size, "a metadata value");
    if (type == openvdb::io::DelayedLoadMetadata::staticTypeName()) {
      delayed_load(walk, size);
    } else if (type != openvdb::StringMetadata::staticTypeName() && openvdb::Metadata::isRegisteredType(type)) {
      const auto fixed = openvdb::Metadata::createMetadata(type)->size();  // TypedMetadata reads size(), whatever the file declares
      if (size != fixed)
        walk.refuse("a VDB file whose " + type + " metadata at byte " + std::to_string(walk.pos) + " is " + std::to_string(fixed) +
                    " bytes (it declares " + std::to_string(size) + ")");
      if (type == openvdb::BoolMetadata::staticTypeName() && static_cast<unsigned char>(*walk.here()) > 1)
        walk.refuse("a VDB file whose bool metadata at byte " + std::to_string(walk.pos) + " is 0 or 1");
      walk.pos += size;
    } else {
      walk.pos += size;  // strings and unknown types: the declared size
    }
  }
}

// The grid's transform: its map's type, then the map, read by OpenVDB from the bytes there are (a
// linear map's fixed fields) to learn its length; other maps are refused before they are read (a
// frustum's second map type is a string of any declared length).
void transform(Walk& walk, char* bytes, uint32_t version, const Where& at) {
  const size_t start = walk.pos;
  const std::string type = walk.string("the grid's transform type");
  namespace m = openvdb::math;
  for (const std::string& linear : {m::AffineMap::mapType(), m::UnitaryMap::mapType(), m::ScaleMap::mapType(), m::UniformScaleMap::mapType(),
                                    m::TranslationMap::mapType(), m::ScaleTranslateMap::mapType(), m::UniformScaleTranslateMap::mapType()})
    if (type == linear) {
      MemoryBuffer buffer(bytes + start, bytes + walk.size());
      std::istream in(&buffer);
      in.exceptions(std::ios::failbit | std::ios::badbit);
      openvdb::io::setVersion(in, openvdb::VersionId(openvdb::OPENVDB_LIBRARY_MAJOR_VERSION, openvdb::OPENVDB_LIBRARY_MINOR_VERSION), version);
      try {
        openvdb::math::Transform().read(in);
      } catch (const std::ios_base::failure&) {
        walk.refuse("a VDB file that holds what it declares (the grid's " + type + " at byte " + std::to_string(walk.pos) + " runs past its end)");
      }
      walk.pos = start + static_cast<size_t>(in.tellg());
      return;
    }
  throw Error(at.field + ".grid", at.value() + " with a " + type + " transform", "an affine index-to-world transform");
}

// The tree's head (TreeBase and RootNode::readTopology): one buffer (OpenVDB prints a warning for
// more), the background, then the root's tiles, whose active flags OpenVDB loads as bools.
void root_tiles(Walk& walk) {
  if (walk.get<int32_t>("the tree's buffer count") != 1) walk.refuse("a VDB grid with one buffer per node (this file's tree has more)");
  walk.skip(sizeof(float), "the background value");
  const auto tiles = walk.get<uint32_t>("the root's tile count");
  walk.skip(sizeof(uint32_t), "the root's child count");
  constexpr size_t kTile = 3 * sizeof(int32_t) + sizeof(float) + 1;  // origin, value, active
  walk.need(uint64_t{tiles} * kTile, "the root's tiles");
  for (uint32_t i = 0; i < tiles; ++i, walk.pos += kTile)
    if (static_cast<unsigned char>(walk.here()[kTile - 1]) > 1) walk.refuse("a VDB file whose root tile at byte " + std::to_string(walk.pos) + " is active 0 or 1");
}

bool uuid_text(const char* s) {  // 36 characters, hex digits with dashes at 8, 13, 18 and 23
  for (int i = 0; i < 36; ++i) {
    const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
    if (dash ? s[i] != '-' : !std::isxdigit(static_cast<unsigned char>(s[i]))) return false;
  }
  return true;
}

}  // namespace

std::string grid_listing(std::vector<std::string> names) {
  if (names.empty()) return "none: the file holds no grids";
  std::sort(names.begin(), names.end());
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "\"" : ", \"") + n + "\"";
  return out;
}

MemoryBuffer::pos_type MemoryBuffer::seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) {
  const off_type base = dir == std::ios_base::beg ? 0 : dir == std::ios_base::cur ? gptr() - eback() : egptr() - eback();
  if (base + off < 0 || base + off > egptr() - eback()) return pos_type(off_type(-1));
  setg(eback(), eback() + base + off, egptr());
  return pos_type(base + off);
}

std::string read_file(const Where& at, const char* kind) {
  std::ifstream in(at.file, std::ios::binary);
  if (!in) throw Error(at.field + ".file", at.file, std::string("a readable ") + kind + " file (it cannot be opened)");
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

openvdb::FloatGrid::Ptr read_openvdb_grid(const Where& at) {
  std::string bytes = read_file(at, "OpenVDB");
  Walk walk(bytes, at);

  // The header (Archive::readHeader).
  if (bytes.size() < 12 || walk.get<int64_t>("the magic number") != openvdb::OPENVDB_MAGIC)
    walk.refuse("a readable OpenVDB file (it does not start with OpenVDB's magic number)");
  const auto version = walk.get<uint32_t>("the format version");
  // From format 219 (OpenVDB 2.0, 2013): transforms by map type, grids' transforms before their trees.
  constexpr uint32_t kOldest = openvdb::OPENVDB_FILE_VERSION_NEW_TRANSFORM;
  if (version < kOldest || version > openvdb::OPENVDB_FILE_VERSION)
    walk.refuse("a readable OpenVDB file of format " + std::to_string(kOldest) + " to " + std::to_string(openvdb::OPENVDB_FILE_VERSION) + " (it has " +
                std::to_string(version) + ")");
  walk.skip(8, "the library version");
  if (walk.get<char>("the grid offsets flag") == 0)
    walk.refuse("a VDB file with grid offsets, as openvdb::io::File writes (this one was written as a stream)");
  if (version < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) walk.skip(1, "the compression flag");
  walk.need(36, "the UUID");
  if (!uuid_text(walk.here())) walk.refuse("a readable OpenVDB file (its UUID at byte " + std::to_string(walk.pos) + " is not 36 characters of text)");
  walk.pos += 36;
  const size_t header = walk.pos;

  // The file's metadata and the grid descriptors, each grid's data between its offsets.
  metadata(walk);
  const auto grids = walk.get<int32_t>("the grid count");
  if (grids < 0) walk.refuse("a VDB file with a grid count >= 0 (it has " + std::to_string(grids) + ")");
  std::vector<std::string> names;
  size_t descriptor = 0, begin = 0, end = 0;
  for (int32_t i = 0; i < grids; ++i) {
    const size_t at_descriptor = walk.pos;
    const std::string unique = walk.string("a grid name");
    std::string type = walk.string("a grid type");
    const std::string parent = walk.string("a grid's instance parent");
    const auto grid_pos = walk.get<int64_t>("a grid offset");
    walk.skip(8, "a grid offset");
    const auto end_pos = walk.get<int64_t>("a grid offset");
    if (grid_pos != static_cast<int64_t>(walk.pos) || end_pos <= grid_pos || end_pos > static_cast<int64_t>(bytes.size()))
      walk.refuse("a VDB file whose grid " + std::to_string(i) + " lies between its offsets (they give bytes " + std::to_string(grid_pos) + " to " +
                  std::to_string(end_pos) + " after a descriptor ending at " + std::to_string(walk.pos) + ")");
    const std::string name = openvdb::io::GridDescriptor::stripSuffix(unique);
    names.push_back(openvdb::io::GridDescriptor::nameAsString(name));
    if (name == at.grid && end == 0) {
      if (!parent.empty())
        throw Error(at.field + ".grid", at.value() + ", an instance of \"" + openvdb::io::GridDescriptor::nameAsString(parent) + "\"",
                    "a grid with a tree of its own");
      if (type.ends_with("_HalfFloat")) type.resize(type.size() - 10);  // stored as half floats (GridDescriptor::read)
      if (!openvdb::GridBase::isRegistered(type)) throw Error(at.field + ".grid", at.value() + " of type " + type, "a grid type OpenVDB knows");
      const openvdb::GridBase::Ptr made = openvdb::GridBase::createGrid(type);
      if (!made->isType<openvdb::FloatGrid>())
        throw Error(at.field + ".grid", at.value() + " of value type " + made->valueType(), "a float grid (density values)");
      descriptor = at_descriptor, begin = static_cast<size_t>(grid_pos), end = static_cast<size_t>(end_pos);
    }
    walk.pos = static_cast<size_t>(end_pos);
  }
  if (end == 0) throw Error(at.field + ".grid", "\"" + at.grid + "\" in " + at.file, "a grid the file has: " + grid_listing(names));

  // The grid's compression flags, metadata, transform and its tree's head (Archive::readGrid,
  // doReadGrid); the rest OpenVDB reads from a stream that ends at the grid's end.
  walk.pos = begin;
  if (version >= openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION) walk.skip(4, "the grid's compression flags");
  metadata(walk);
  transform(walk, bytes.data(), version, at);
  root_tiles(walk);

  // OpenVDB reads a file of this grid alone: the header, no metadata, one grid, its descriptor
  // and data, laid out in place just before the descriptor.
  const size_t start = descriptor - header - 8;  // descriptor >= header + 8: metadata count, grid count
  std::memmove(bytes.data() + start, bytes.data(), header);
  const uint32_t no_metadata = 0;
  const int32_t one_grid = 1;
  std::memcpy(bytes.data() + start + header, &no_metadata, 4);
  std::memcpy(bytes.data() + start + header + 4, &one_grid, 4);
  MemoryBuffer buffer(bytes.data() + start, bytes.data() + end);
  std::istream in(&buffer);
  in.exceptions(std::ios::failbit | std::ios::badbit);
  try {
    openvdb::io::Stream stream(in, false);
    return openvdb::gridPtrCast<openvdb::FloatGrid>(stream.getGrids()->at(0));
  } catch (const std::ios_base::failure&) {
    throw Error(at.field + ".file", at.value(), "a grid whose data lies within its offsets (OpenVDB read past byte " + std::to_string(end) + ")");
  }
}

}  // namespace haze::vdb
