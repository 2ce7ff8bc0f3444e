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
// Coarse blocks in all, and majorant cells per axis; fewer in the long fuzz runs
// (scripts/fuzz-offline), whose inputs reach the limits and would spend their time filling 64 MB
// and 64^3 majorants: the same code on smaller arrays.
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
constexpr int64_t kMaxBlocks = int64_t{1} << 15;
constexpr int kMaxMajorants = 16;
#else
constexpr int64_t kMaxBlocks = int64_t{1} << 24;
constexpr int kMaxMajorants = 64;
#endif

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
