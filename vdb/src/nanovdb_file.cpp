// read_nanovdb_grid: a NanoVDB file's segments walked and checked (the format as NanoVDB 32 reads
// it: nanovdb/util/IO.h Segment::read, GridMetaData::read, Internal::read), the grid read by
// NanoVDB from memory, then every node offset of its tree checked before anything follows one.
#include "checked_read.h"

#include <nanovdb/util/IO.h>

#include <istream>

namespace haze::vdb {
namespace {

// A node of `node` bytes at `offset` from the grid's start must lie 32-byte aligned in [lo, size).
void check_offset(uint64_t offset, uint64_t node, uint64_t lo, uint64_t size, const char* what, const Where& at) {
  if (offset % NANOVDB_DATA_ALIGNMENT != 0 || offset < lo || offset > size || node > size - offset)
    throw Error(at.field + ".file", at.value(),
                std::string("a NanoVDB grid whose nodes lie within it (") + what + " at byte " + std::to_string(offset) + " of " + std::to_string(size) + ")");
}

// Each child pointer of the tree (root tiles, upper and lower internal nodes) as an offset from
// the grid: NanoVDB's own GridValidator follows the root's table size and the leaves unchecked.
void check_tree(const nanovdb::NanoGrid<float>& grid, uint64_t size, const Where& at) {
  using Root = nanovdb::NanoRoot<float>;
  using Upper = nanovdb::NanoUpper<float>;
  using Lower = nanovdb::NanoLower<float>;
  using Leaf = nanovdb::NanoLeaf<float>;
  const auto* base = reinterpret_cast<const uint8_t*>(&grid);
  auto offset_of = [&](const void* p) { return static_cast<uint64_t>(reinterpret_cast<const uint8_t*>(p) - base); };
  const uint64_t tree = sizeof(nanovdb::GridData);
  if (size < tree + sizeof(nanovdb::TreeData<3>) || grid.gridSize() != size)
    throw Error(at.field + ".file", at.value(), "a NanoVDB grid of the size its file gives (" + std::to_string(size) + " bytes)");
  const uint64_t root = tree + grid.tree().data()->mNodeOffset[3];  // modulo 2^64, as every offset here: a wrap lands out of range
  check_offset(root, sizeof(Root), tree + sizeof(nanovdb::TreeData<3>), size, "the root", at);
  const auto* root_data = reinterpret_cast<const Root*>(base + root)->data();
  const uint64_t tiles = uint64_t{root_data->mTableSize} * sizeof(Root::DataType::Tile);
  check_offset(root, sizeof(Root) + tiles, 0, size, "the root's tile table", at);
  const uint64_t nodes = root + sizeof(Root) + tiles;  // child nodes follow the root and its table
  auto child = [&](uint64_t parent, int64_t relative, uint64_t node, const char* what) {
    check_offset(parent + static_cast<uint64_t>(relative), node, nodes, size, what, at);
  };
  for (uint32_t i = 0; i < root_data->mTableSize; ++i) {
    const auto* tile = root_data->tile(i);
    if (!tile->isChild()) continue;
    child(root, tile->child, sizeof(Upper), "an upper node");
    const Upper& upper = *root_data->getChild(tile);
    for (auto n = upper.data()->mChildMask.beginOn(); n; ++n) {
      child(offset_of(&upper), upper.data()->mTable[*n].child, sizeof(Lower), "a lower node");
      const Lower& lower = *upper.data()->getChild(*n);
      for (auto m = lower.data()->mChildMask.beginOn(); m; ++m) child(offset_of(&lower), lower.data()->mTable[*m].child, sizeof(Leaf), "a leaf");
    }
  }
}

}  // namespace

nanovdb::GridHandle<nanovdb::HostBuffer> read_nanovdb_grid(const Where& at) {
  std::string bytes = read_file(at, "NanoVDB");
  Walk walk(bytes, at);
  std::vector<std::string> names;
  const nanovdb::io::GridMetaData* found = nullptr;
  std::vector<nanovdb::io::GridMetaData> metas;
  // Segments to the end of the file (Segment::read ends at fewer than 16 bytes): a header, then
  // per grid its metadata and name, then the grids' data.
  while (walk.left() >= sizeof(nanovdb::io::Header)) {
    const auto header = walk.get<nanovdb::io::Header>("a segment header");
    if (header.magic != NANOVDB_MAGIC_NUMBER)
      walk.refuse("a readable NanoVDB file (the segment ending at byte " + std::to_string(walk.pos) + " does not start with NanoVDB's magic number)");
    if (header.version.getMajor() != NANOVDB_MAJOR_VERSION_NUMBER)
      walk.refuse("a NanoVDB file of major version " + std::to_string(NANOVDB_MAJOR_VERSION_NUMBER) + " (it has " + std::to_string(header.version.getMajor()) + ")");
    if (header.codec != nanovdb::io::Codec::NONE) walk.refuse("an uncompressed NanoVDB file (this build reads neither ZIP nor Blosc NanoVDB files)");
    const size_t first = metas.size();
    for (uint16_t i = 0; i < header.gridCount; ++i) {
      nanovdb::io::GridMetaData m;
      static_cast<nanovdb::io::MetaData&>(m) = walk.get<nanovdb::io::MetaData>("a grid's metadata");
      walk.need(m.nameSize, "a grid name");
      if (m.nameSize == 0 || walk.here()[m.nameSize - 1] != '\0') walk.refuse("a NanoVDB file whose grid names end in a NUL (the name at byte " + std::to_string(walk.pos) + " does not)");
      m.gridName = walk.here();
      walk.pos += m.nameSize;
      metas.push_back(std::move(m));
    }
    for (size_t i = first; i < metas.size(); ++i) {
      walk.skip(metas[i].fileSize, "a grid");
      if (metas[i].gridSize != metas[i].fileSize) walk.refuse("an uncompressed NanoVDB file whose grid sizes match their bytes in the file");
    }
  }
  if (metas.empty()) walk.refuse("a NanoVDB file holding grids (none found: not a NanoVDB file, or an empty one)");
  for (const auto& m : metas) {
    names.push_back(m.gridName);
    if (m.gridName == at.grid && !found) found = &m;
  }
  if (!found) throw Error(at.field + ".grid", "\"" + at.grid + "\" in " + at.file, "a grid the file has: " + grid_listing(names));
  if (found->gridType != nanovdb::GridType::Float) {
    const auto type = found->gridType;  // toStr indexes a table with it
    throw Error(at.field + ".grid", at.value() + " of value type " + (type < nanovdb::GridType::End ? nanovdb::toStr(type) : "unknown (" + std::to_string(static_cast<uint32_t>(type)) + ")"),
                "a float grid (density values)");
  }
  if (found->nameKey != nanovdb::io::stringHash(found->gridName))
    throw Error(at.field + ".file", at.value(), "a NanoVDB file whose name keys hash their names");

  MemoryBuffer buffer(bytes.data(), bytes.data() + bytes.size());
  std::istream in(&buffer);
  nanovdb::GridHandle<nanovdb::HostBuffer> handle = nanovdb::io::readGrid<nanovdb::HostBuffer>(in, at.grid);
  // The handle holds this one grid, but its header keeps the index and count it had among the
  // file's grids, and grid<float>() walks from it by gridSize() to index 0 unchecked: past the
  // buffer, or forever where the size is 0 (fuzz_vdb). It is the first and only grid here.
  if (handle.size() < sizeof(nanovdb::GridData)) throw Error(at.field + ".file", at.value(), "a NanoVDB grid of at least its header's size");
  auto* header = reinterpret_cast<nanovdb::GridData*>(handle.data());
  header->mGridIndex = 0;
  header->mGridCount = 1;
  // Its name is the file's (checked above); a header flagging a long name sends gridName() to the
  // blind metadata at an offset nothing checks (NanoToOpenVDB segfaulted: fuzz_vdb). Haze reads no
  // blind data, so the grid keeps none, and its short name ends within its field.
  header->mFlags &= ~static_cast<uint32_t>(nanovdb::GridFlags::HasLongGridName);
  header->mBlindMetadataOffset = 0;
  header->mBlindMetadataCount = 0;
  header->mGridName[nanovdb::GridData::MaxNameSize - 1] = '\0';
  const auto* grid = handle.grid<float>();
  if (!grid) throw Error(at.field + ".grid", at.value(), "a float grid (density values)");
  check_tree(*grid, handle.size(), at);
  return handle;
}

}  // namespace haze::vdb
