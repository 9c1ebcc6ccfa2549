#pragma once
// Reads the fields of one serialized ROS message, in ROS 1's packing (little-endian, no padding, strings and
// arrays prefixed by a uint32 count) or in ROS 2's CDR (a 4-byte encapsulation header whose second byte says
// the byte order; each primitive aligned to its size, counted from the end of that header; strings carry a
// trailing NUL that their count includes). Every length is checked against the bytes left before it is used.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "vmap/sources/recording_reader.h"

namespace vmap {

class MessageBuffer {
 public:
  // Throws InputError (with `what` as the message's name) when a CDR encapsulation header is missing or
  // names an encoding other than plain CDR.
  MessageBuffer(const uint8_t* data, size_t size, MessageEncoding encoding, std::string what);

  uint8_t U8();
  uint32_t U32();
  int32_t I32() { return static_cast<int32_t>(U32()); }
  double F64();
  std::string String();
  // A uint8[] field: the bytes stay in the message (no copy); `*size` is their count.
  const uint8_t* Bytes(size_t* size);
  std::vector<double> F64Array();               // float64[]
  void F64Fixed(double* values, size_t count);  // float64[N]

  size_t remaining() const { return size_ - position_; }

 private:
  void Align(size_t alignment);
  const uint8_t* Take(size_t count, const char* field);

  const uint8_t* data_;
  size_t size_;
  size_t position_ = 0;
  size_t origin_ = 0;  // where CDR alignment counts from
  bool cdr_;
  bool big_endian_ = false;
  std::string what_;
};

// A std_msgs/Header (ROS 1: seq, stamp, frame_id; ROS 2: stamp, frame_id), read whole: its stamp in seconds.
double ReadHeaderStamp(MessageBuffer& buffer, MessageEncoding encoding);

}  // namespace vmap
