// What a VolumeField holds (internal): the NanoVDB grid it samples, its transforms, and the maxima
// of its leaves and tiles on a coarse grid of 8^3-voxel blocks (the majorants' source).
#pragma once

#include <haze/vdb/vdb.h>

#include <nanovdb/util/GridHandle.h>
#include <nanovdb/util/HostBuffer.h>

#include <glm/mat4x4.hpp>

#include <cstdint>
#include <vector>

namespace haze::vdb {

constexpr int kBlock = 8;  // voxels per coarse block along each axis (an OpenVDB leaf)
constexpr int64_t kMaxSpan = int64_t{1} << 24;    // voxels along an axis between the first and last non-zero value
constexpr int64_t kMaxBlocks = int64_t{1} << 24;  // coarse blocks in all

struct VolumeField::Data {
  VolumeInfo info;
  nanovdb::GridHandle<nanovdb::HostBuffer> handle;
  const nanovdb::NanoGrid<float>* grid = nullptr;
  glm::dmat4 index_to_world{1.0}, world_to_index{1.0};  // voxel centres at integer index points
  Aabb bounds;  // the world box of the index box where density may be non-zero (trilinear support)
  // Coarse block (x, y, z) covers index voxels origin + block * (x, y, z) + [0, block): block is
  // kBlock, or a power-of-two multiple where more would pass kMaxBlocks.
  int block = kBlock;
  std::array<int, 3> origin{0, 0, 0}, blocks{1, 1, 1};
  std::vector<float> block_max;  // x fastest
};

}  // namespace haze::vdb
