// Reading VDB files without trusting the lengths and offsets they declare (internal). OpenVDB's
// reader allocates, and fills, whatever a file declares (a metadata string of 4 GB in a 1 KB
// file) and reads on past a file's end with garbage counts; a NanoVDB file is a memory image whose
// nodes are found through the byte offsets it stores. So each file's layout is walked first, every
// length and offset checked against the bytes there are, before the libraries read it.
#pragma once

#include <haze/core/error.h>

#include <nanovdb/util/GridHandle.h>
#include <nanovdb/util/HostBuffer.h>
#include <openvdb/openvdb.h>

#include <cstdint>
#include <cstring>
#include <streambuf>
#include <string>
#include <vector>

namespace haze::vdb {

// Where a read is: the scene field ("medium.density"), the file and the grid name.
struct Where {
  std::string field;
  std::string file, grid;
  std::string value() const { return "grid \"" + grid + "\" of " + file; }
};

// The file's bytes; a haze::Error if it cannot be read.
std::string read_file(const Where& at, const char* kind);

// Bytes read front to back, each declared length checked against what remains; failures are
// haze::Errors on at.field + ".file".
class Walk {
 public:
  Walk(const std::string& bytes, const Where& at) : end(bytes.size()), bytes_(bytes), at_(at) {}

  size_t pos = 0;
  size_t end;  // where the bytes being walked end

  size_t size() const { return bytes_.size(); }
  size_t left() const { return end - pos; }
  const char* here() const { return bytes_.data() + pos; }
  [[noreturn]] void refuse(const std::string& expected) const { throw Error(at_.field + ".file", at_.file, expected); }
  void need(uint64_t n, const char* what) const {
    if (n > left())
      refuse("a VDB file that holds what it declares (" + std::string(what) + " at byte " + std::to_string(pos) + " needs " + std::to_string(n) +
             " bytes; " + std::to_string(left()) + " remain)");
  }
  template <class T>
  T get(const char* what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(static_cast<void*>(&v), here(), sizeof(T));
    pos += sizeof(T);
    return v;
  }
  std::string string(const char* what) {  // OpenVDB's io::readString: a uint32 length, then the bytes
    const auto n = get<uint32_t>(what);
    need(n, what);
    std::string s(here(), n);
    pos += n;
    return s;
  }
  void skip(uint64_t n, const char* what) {
    need(n, what);
    pos += n;
  }

 private:
  const std::string& bytes_;
  const Where& at_;
};

// A read-only stream buffer over bytes in memory, seekable within them.
class MemoryBuffer : public std::streambuf {
 public:
  MemoryBuffer(char* begin, char* end) { setg(begin, begin, end); }

 protected:
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) override;
  pos_type seekpos(pos_type p, std::ios_base::openmode mode) override { return seekoff(off_type(p), std::ios_base::beg, mode); }
};

// The names, sorted and quoted, for "a grid the file has: ...".
std::string grid_listing(std::vector<std::string> names);

// The named float grid of an OpenVDB file (format 222 to 224), read by OpenVDB from the grid's
// checked bytes alone, in memory, through a stream that throws at their end.
openvdb::FloatGrid::Ptr read_openvdb_grid(const Where& at);

// The named float grid of an uncompressed NanoVDB file, its segments checked before NanoVDB reads
// them and its nodes' offsets checked to lie within its buffer before anything follows them.
nanovdb::GridHandle<nanovdb::HostBuffer> read_nanovdb_grid(const Where& at);

}  // namespace haze::vdb
