#include "vmap/sources/message_buffer.h"

#include <cstring>

#include "vmap/core/error.h"

namespace vmap {

MessageBuffer::MessageBuffer(const uint8_t* data, size_t size, MessageEncoding encoding, std::string what)
    : data_(data), size_(size), cdr_(encoding == MessageEncoding::kCdr), what_(std::move(what)) {
  if (!cdr_) return;
  // Encapsulation: 0x00 0x00 plain CDR big-endian, 0x00 0x01 little-endian; then two option bytes.
  if (size_ < 4 || data_[0] != 0 || data_[1] > 1) {
    throw InputError(what_ + " is not plain CDR (encapsulation header " +
                     (size_ < 2 ? std::string("missing") : std::to_string(data_[0]) + "," + std::to_string(data_[1])) +
                     "); vmap reads ROS 2 messages serialized as CDR");
  }
  big_endian_ = data_[1] == 0;
  position_ = origin_ = 4;
}

const uint8_t* MessageBuffer::Take(size_t count, const char* field) {
  if (count > size_ - position_) {
    throw InputError(what_ + " is truncated: its " + field + " needs " + std::to_string(count) + " bytes at byte " +
                     std::to_string(position_) + " but the message has " + std::to_string(size_) + "");
  }
  const uint8_t* at = data_ + position_;
  position_ += count;
  return at;
}

void MessageBuffer::Align(size_t alignment) {
  if (!cdr_) return;
  const size_t misalignment = (position_ - origin_) % alignment;
  if (misalignment != 0) Take(alignment - misalignment, "padding");
}

uint8_t MessageBuffer::U8() { return *Take(1, "byte"); }

uint32_t MessageBuffer::U32() {
  Align(4);
  const uint8_t* b = Take(4, "uint32");
  if (big_endian_) return uint32_t{b[0]} << 24 | uint32_t{b[1]} << 16 | uint32_t{b[2]} << 8 | b[3];
  return uint32_t{b[3]} << 24 | uint32_t{b[2]} << 16 | uint32_t{b[1]} << 8 | b[0];
}

double MessageBuffer::F64() {
  Align(8);
  const uint8_t* b = Take(8, "float64");
  uint64_t bits = 0;
  for (int i = 0; i < 8; ++i) bits |= uint64_t{b[big_endian_ ? 7 - i : i]} << (8 * i);
  double value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

std::string MessageBuffer::String() {
  const uint32_t length = U32();
  const char* text = reinterpret_cast<const char*>(Take(length, "string"));
  // CDR counts the terminating NUL; ROS 1 has none.
  size_t chars = length;
  if (cdr_ && chars > 0 && text[chars - 1] == '\0') --chars;
  return std::string(text, chars);
}

const uint8_t* MessageBuffer::Bytes(size_t* size) {
  *size = U32();
  return Take(*size, "byte array");
}

std::vector<double> MessageBuffer::F64Array() {
  const uint32_t count = U32();
  if (count > remaining() / 8) Take(size_t{count} * 8, "float64 array");  // throws: more than the message holds
  std::vector<double> values(count);
  for (double& value : values) value = F64();
  return values;
}

void MessageBuffer::F64Fixed(double* values, size_t count) {
  for (size_t i = 0; i < count; ++i) values[i] = F64();
}

double ReadHeaderStamp(MessageBuffer& buffer, MessageEncoding encoding) {
  if (encoding == MessageEncoding::kRos1) buffer.U32();  // seq: ROS 1 only
  const uint32_t seconds = buffer.U32();                 // ROS 1 uint32, ROS 2 int32: both non-negative in practice
  const uint32_t nanoseconds = buffer.U32();
  buffer.String();  // frame_id
  const double sec = encoding == MessageEncoding::kCdr ? static_cast<double>(static_cast<int32_t>(seconds)) : seconds;
  return sec + nanoseconds * 1e-9;
}

}  // namespace vmap
