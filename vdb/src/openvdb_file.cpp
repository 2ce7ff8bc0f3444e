// read_openvdb_grid: an OpenVDB file's layout walked and checked (the format as OpenVDB 10 reads
// it: io/Archive.cc readHeader, MetaMap::readMeta, GridDescriptor::read, Archive::writeGrid's
// offsets), then the one grid read by OpenVDB from memory.
#include "checked_read.h"

#include <openvdb/io/DelayedLoadMetadata.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/io/Stream.h>
#include <openvdb/math/Maps.h>

#include <blosc.h>

#include <algorithm>
#include <array>
#include <bit>
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
// value is passed over as OpenVDB reads it. Returns the last is_saved_as_half_float value (a
// grid's values are then 16-bit floats; GridBase::saveFloatAsHalf).
bool metadata(Walk& walk) {
  bool half = false;
  const auto count = walk.get<uint32_t>("a metadata count");
  for (uint32_t i = 0; i < count; ++i) {
    const std::string name = walk.string("a metadata name");
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
      if (name == openvdb::GridBase::META_SAVE_HALF_FLOAT) {
        if (type != openvdb::BoolMetadata::staticTypeName())
          walk.refuse("a VDB file whose " + name + " metadata at byte " + std::to_string(walk.pos) + " is a bool (it is a " + type + ")");
        half = *walk.here() == 1;
      }
      walk.pos += size;
    } else {
      if (name == openvdb::GridBase::META_SAVE_HALF_FLOAT)
        walk.refuse("a VDB file whose " + name + " metadata at byte " + std::to_string(walk.pos) + " is a bool (it is a " + type + ")");
      walk.pos += size;  // strings and unknown types: the declared size
    }
  }
  return half;
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
      MemoryBuffer buffer(bytes + start, bytes + walk.end);
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

// The tree (Tree::readTopology, then readBuffers), walked as OpenVDB 10 reads a FloatTree of
// format 222 on: OpenVDB 10 reads a raw chunk's declared length into its node before comparing it
// with the node's size, and allocates a compressed chunk's declared length before reading it.
struct Values {
  uint32_t compression;  // the grid's io::COMPRESS_* flags
  bool half;             // values stored as 16-bit floats
};

uint64_t bits_on(const char* mask, uint64_t bytes) {
  uint64_t n = 0;
  for (uint64_t i = 0; i < bytes; i += 8) {
    uint64_t word;
    std::memcpy(&word, mask + i, 8);
    n += static_cast<uint64_t>(std::popcount(word));
  }
  return n;
}

// io::readData: behind Blosc or zip an int64 byte count (<= 0: that many raw bytes, which must be
// exactly the values' bytes), else the raw bytes. Blosc's header is checked before Blosc trusts it.
void values_chunk(Walk& walk, uint64_t bytes, const Values& v) {
  namespace io = openvdb::io;
  if (!(v.compression & (io::COMPRESS_BLOSC | io::COMPRESS_ZIP))) return walk.skip(bytes, "a node's values");
  const size_t at = walk.pos;
  const auto n = walk.get<int64_t>("a compressed chunk's length");
  if (n <= 0) {
    if (uint64_t{0} - static_cast<uint64_t>(n) != bytes)
      walk.refuse("a VDB file whose uncompressed chunk at byte " + std::to_string(at) + " holds its node's " + std::to_string(bytes) +
                  " bytes of values (it declares " + std::to_string(uint64_t{0} - static_cast<uint64_t>(n)) + ")");
    return walk.skip(bytes, "a node's values");
  }
  walk.need(static_cast<uint64_t>(n), "a compressed chunk");
  size_t decoded = 0;
  if ((v.compression & io::COMPRESS_BLOSC) && (blosc_cbuffer_validate(walk.here(), static_cast<size_t>(n), &decoded) != 0 || decoded != bytes))
    walk.refuse("a VDB file whose Blosc chunk at byte " + std::to_string(at) + " is whole and holds its node's " + std::to_string(bytes) +
                " bytes of values");
  walk.pos += static_cast<size_t>(n);
}

// io::readCompressedValues for a node of `count` values, `active` of them active: a layout byte,
// inactive values and a selection mask as the layout says, then the active values alone (with
// active-mask compression) or all of them.
void node_values(Walk& walk, uint64_t count, uint64_t active, const Values& v) {
  const size_t at = walk.pos;
  const auto layout = walk.get<int8_t>("a node's value layout");
  if (layout < 0 || layout > 6) walk.refuse("a VDB file whose node values at byte " + std::to_string(at) + " have a layout of 0 to 6 (" + std::to_string(layout) + ")");
  if (layout == 2 || layout == 4 || layout == 5) walk.skip(layout == 5 ? 8 : 4, "a node's inactive values");  // floats, whatever `half` says
  if (layout == 3 || layout == 4 || layout == 5) walk.skip(count / 8, "a node's selection mask");
  const uint64_t stored = (v.compression & openvdb::io::COMPRESS_ACTIVE_MASK) && layout != 6 ? active : count;
  if (v.half && stored == 0) return;  // HalfReader reads nothing then
  values_chunk(walk, stored * (v.half ? 2 : 4), v);
}

// InternalNode::readTopology: child and value masks, the values, then each child (the lower
// internal nodes, or the leaves' value masks). Returns the number of leaves below.
uint64_t internal_node(Walk& walk, int log2dim, const Values& v) {
  const uint64_t count = uint64_t{1} << (3 * log2dim), mask = count / 8;
  walk.need(2 * mask, "a node's masks");
  const uint64_t children = bits_on(walk.here(), mask), active = bits_on(walk.here() + mask, mask);
  walk.pos += 2 * mask;
  node_values(walk, count, active, v);
  if (log2dim == 4) {
    walk.skip(children * 64, "leaf value masks");
    return children;
  }
  uint64_t leaves = 0;
  for (uint64_t i = 0; i < children; ++i) leaves += internal_node(walk, 4, v);
  return leaves;
}

// The whole tree: one buffer (OpenVDB prints a warning for more), the background, the root's
// tiles (active flags loaded as bools) and children (origins on the 4096-voxel lattice, in
// increasing order as OpenVDB writes them: a repeated origin would leak the first child, and
// readBuffers visits children in that order), then each leaf's value mask and values.
void tree(Walk& walk, const Values& v) {
  if (walk.get<int32_t>("the tree's buffer count") != 1) walk.refuse("a VDB grid with one buffer per node (this file's tree has more)");
  walk.skip(sizeof(float), "the background value");
  const auto tiles = walk.get<uint32_t>("the root's tile count");
  const auto children = walk.get<uint32_t>("the root's child count");
  auto origin = [&](const char* what) {
    std::array<int32_t, 3> o;
    const size_t at = walk.pos;
    for (auto& c : o) c = walk.get<int32_t>(what);
    if ((o[0] | o[1] | o[2]) & 4095) walk.refuse("a VDB file whose " + std::string(what) + " at byte " + std::to_string(at) + " is a multiple of 4096");
    return o;
  };
  for (uint32_t i = 0; i < tiles; ++i) {
    origin("root tile's origin");
    walk.skip(sizeof(float), "a root tile's value");
    if (static_cast<unsigned char>(walk.get<char>("a root tile's active flag")) > 1)
      walk.refuse("a VDB file whose root tile at byte " + std::to_string(walk.pos - 1) + " is active 0 or 1");
  }
  uint64_t leaves = 0;
  std::array<int32_t, 3> last{};
  for (uint32_t i = 0; i < children; ++i) {
    const size_t at = walk.pos;
    const auto o = origin("root child's origin");
    if (i > 0 && !(last < o)) walk.refuse("a VDB file whose root children are in increasing order (the one at byte " + std::to_string(at) + " is not)");
    last = o;
    leaves += internal_node(walk, 5, v);
  }
  for (uint64_t i = 0; i < leaves; ++i) {
    walk.need(64, "a leaf's value mask");
    const uint64_t active = bits_on(walk.here(), 64);
    walk.pos += 64;
    node_values(walk, 512, active, v);
  }
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
  std::ifstream in(at.file, std::ios::binary | std::ios::ate);
  if (!in) throw Error(at.field + ".file", at.file, std::string("a readable ") + kind + " file (it cannot be opened)");
  const std::streamoff size = in.tellg();
  if (size < 0) {  // not seekable (a pipe): read to its end
    in.clear();
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::string bytes(static_cast<size_t>(size), '\0');
  in.seekg(0);
  in.read(bytes.data(), size);
  bytes.resize(static_cast<size_t>(in.gcount()));
  return bytes;
}

openvdb::FloatGrid::Ptr read_openvdb_grid(const Where& at) {
  std::string bytes = read_file(at, "OpenVDB");
  Walk walk(bytes, at);

  // The header (Archive::readHeader).
  if (bytes.size() < 12 || walk.get<int64_t>("the magic number") != openvdb::OPENVDB_MAGIC)
    walk.refuse("a readable OpenVDB file (it does not start with OpenVDB's magic number)");
  const auto version = walk.get<uint32_t>("the format version");
  // From format 222 (OpenVDB 3.0, 2014): compression flags per grid, node values behind a layout byte.
  constexpr uint32_t kOldest = openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION;
  if (version < kOldest || version > openvdb::OPENVDB_FILE_VERSION)
    walk.refuse("a readable OpenVDB file of format " + std::to_string(kOldest) + " to " + std::to_string(openvdb::OPENVDB_FILE_VERSION) + " (it has " +
                std::to_string(version) + ")");
  walk.skip(8, "the library version");
  if (walk.get<char>("the grid offsets flag") == 0)
    walk.refuse("a VDB file with grid offsets, as openvdb::io::File writes (this one was written as a stream)");
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

  // The grid's compression flags, metadata, transform and tree (Archive::readGrid, doReadGrid),
  // within the grid's offsets.
  walk.pos = begin;
  walk.end = end;
  Values values;
  values.compression = walk.get<uint32_t>("the grid's compression flags");
  values.half = metadata(walk);
  transform(walk, bytes.data(), version, at);
  tree(walk, values);

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
