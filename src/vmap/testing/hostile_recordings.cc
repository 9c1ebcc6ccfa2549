#include "vmap/testing/hostile_recordings.h"

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <stdexcept>

namespace vmap::testing {
namespace {

void Put16(std::string& out, uint16_t v) { out.append(reinterpret_cast<const char*>(&v), 2); }
void Put32(std::string& out, uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }
void Put64(std::string& out, uint64_t v) { out.append(reinterpret_cast<const char*>(&v), 8); }
uint64_t Load64(const std::string& in, size_t at) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = v << 8 | static_cast<uint8_t>(in[at + i]);
  return v;
}

// A header field "name=value", with its length.
std::string Field(const std::string& name, const std::string& value) {
  std::string field;
  Put32(field, static_cast<uint32_t>(name.size() + 1 + value.size()));
  return field + name + "=" + value;
}

std::string U32Text(uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); }
std::string U64Text(uint64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); }

std::string Record(const std::string& header, const std::string& data) {
  std::string record;
  Put32(record, static_cast<uint32_t>(header.size()));
  record += header;
  Put32(record, static_cast<uint32_t>(data.size()));
  return record + data;
}

// The connection and message records of `messages`, then the record of a /padding message of `padding` bytes
// but for its data; connection ids from 1 by topic (0 is left unused, so that zeros parsed as a record name no
// connection).
std::string Ros1Records(std::vector<TestMessage> messages, uint64_t padding,
                        std::map<std::string, uint32_t>* connections, uint32_t first_connection = 1) {
  if (padding > 0) messages.push_back({"/padding", "std_msgs/ByteMultiArray", 0, {}});
  std::string records;
  for (const TestMessage& message : messages) {
    auto found = connections->find(message.topic);
    if (found == connections->end()) {
      found = connections->emplace(message.topic, static_cast<uint32_t>(connections->size() + first_connection)).first;
      const std::string data = Field("topic", message.topic) + Field("type", message.type) + Field("md5sum", "*") +
                               Field("message_definition", "");
      records +=
          Record(Field("op", "\x07") + Field("conn", U32Text(found->second)) + Field("topic", message.topic), data);
    }
    const uint64_t time = (message.log_time_ns / 1000000000) | (message.log_time_ns % 1000000000) << 32;
    const std::string header =
        Field("op", "\x02") + Field("conn", U32Text(found->second)) + Field("time", U64Text(time));
    if (padding > 0 && &message == &messages.back()) {
      Put32(records, static_cast<uint32_t>(header.size()));
      records += header;
      Put32(records, static_cast<uint32_t>(padding));  // the data: zeros, which the caller adds
    } else {
      records += Record(header, std::string(message.data.begin(), message.data.end()));
    }
  }
  return records;
}

void PutMcapRecord(std::string& out, uint8_t op, const std::string& content) {
  out.push_back(static_cast<char>(op));
  Put64(out, content.size());
  out += content;
}

}  // namespace

std::string CompressBytes(const std::string& compression, const std::string& data) {
  if (compression == "none") return data;
  return CompressedWithZeros(compression, data, 0);
}

std::string CompressedWithZeros(const std::string& compression, const std::string& prefix, uint64_t zeros) {
  const std::string block(1 << 20, '\0');
  std::string out;
  // Feeds the prefix, then the zeros a block at a time, to `step(data, size, last)`.
  const auto feed = [&](const auto& step) {
    step(prefix.data(), prefix.size(), zeros == 0);
    for (uint64_t left = zeros; left > 0;) {
      const size_t n = static_cast<size_t>(std::min<uint64_t>(left, block.size()));
      left -= n;
      step(block.data(), n, left == 0);
    }
  };
  if (compression == "zstd") {
    const std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)> context(ZSTD_createCCtx(), &ZSTD_freeCCtx);
    ZSTD_CCtx_setParameter(context.get(), ZSTD_c_compressionLevel, 1);
    std::string piece(ZSTD_CStreamOutSize(), '\0');
    feed([&](const char* data, size_t size, bool last) {
      ZSTD_inBuffer input{data, size, 0};
      for (bool done = false; !done;) {
        ZSTD_outBuffer output{piece.data(), piece.size(), 0};
        const size_t left = ZSTD_compressStream2(context.get(), &output, &input, last ? ZSTD_e_end : ZSTD_e_continue);
        if (ZSTD_isError(left)) throw std::runtime_error("zstd compression failed");
        out.append(piece.data(), output.pos);
        done = last ? left == 0 : input.pos == input.size;
      }
    });
  } else if (compression == "lz4") {
    LZ4F_cctx* raw = nullptr;
    LZ4F_createCompressionContext(&raw, LZ4F_VERSION);
    const std::unique_ptr<LZ4F_cctx, decltype(&LZ4F_freeCompressionContext)> context(raw, &LZ4F_freeCompressionContext);
    std::string piece(LZ4F_compressBound(block.size(), nullptr) + 64, '\0');
    out.resize(LZ4F_HEADER_SIZE_MAX);
    out.resize(LZ4F_compressBegin(context.get(), out.data(), out.size(), nullptr));
    feed([&](const char* data, size_t size, bool last) {
      for (size_t at = 0; at < size;) {
        const size_t n = std::min(size - at, block.size());
        piece.resize(LZ4F_compressBound(n, nullptr) + 64);
        out.append(piece.data(), LZ4F_compressUpdate(context.get(), piece.data(), piece.size(), data + at, n, nullptr));
        at += n;
      }
      if (last) out.append(piece.data(), LZ4F_compressEnd(context.get(), piece.data(), piece.size(), nullptr));
    });
  } else if (compression == "bz2") {
    bz_stream stream{};
    if (BZ2_bzCompressInit(&stream, 9, 0, 0) != BZ_OK) throw std::runtime_error("bz2 compression failed");
    std::string piece(1 << 16, '\0');
    feed([&](const char* data, size_t size, bool last) {
      stream.next_in = const_cast<char*>(data);
      stream.avail_in = static_cast<unsigned int>(size);
      for (;;) {
        stream.next_out = piece.data();
        stream.avail_out = static_cast<unsigned int>(piece.size());
        const int status = BZ2_bzCompress(&stream, last ? BZ_FINISH : BZ_RUN);
        out.append(piece.data(), piece.size() - stream.avail_out);
        if (last ? status == BZ_STREAM_END : stream.avail_in == 0) break;
        if (status < 0) throw std::runtime_error("bz2 compression failed");
      }
    });
    BZ2_bzCompressEnd(&stream);
  } else {
    throw std::invalid_argument("CompressedWithZeros: " + compression);
  }
  return out;
}

std::string Ros1BagBytes(const std::vector<Ros1Chunk>& chunks) {
  std::map<std::string, uint32_t> connections;
  std::string body;
  for (const Ros1Chunk& chunk : chunks) {
    std::string stored = chunk.stored;
    uint64_t size = chunk.announced_size;
    if (stored.empty()) {
      const std::string records = Ros1Records(chunk.messages, chunk.padding, &connections);
      stored = chunk.compression == "none" ? records + std::string(chunk.padding, '\0')
                                           : CompressedWithZeros(chunk.compression, records, chunk.padding);
      if (size == 0) size = records.size() + chunk.padding;
    }
    body += Record(Field("op", "\x05") + Field("compression", chunk.compression) +
                       Field("size", U32Text(static_cast<uint32_t>(size))),
                   stored);
  }
  // The bag header: no index (index_pos 0), padded to 4096 bytes as rosbag writes it.
  const std::string header = Field("op", "\x03") + Field("index_pos", U64Text(0)) +
                             Field("conn_count", U32Text(static_cast<uint32_t>(connections.size()))) +
                             Field("chunk_count", U32Text(static_cast<uint32_t>(chunks.size())));
  return "#ROSBAG V2.0\n" + Record(header, std::string(4096 - 8 - header.size(), ' ')) + body;
}

std::string Ros1ChunkRecords(const std::vector<TestMessage>& messages, uint64_t padding, uint32_t first_connection) {
  std::map<std::string, uint32_t> connections;
  return Ros1Records(messages, padding, &connections, first_connection);
}

void WriteRos1BagChunks(const std::string& path, const std::vector<Ros1Chunk>& chunks) {
  std::ofstream(path, std::ios::binary) << Ros1BagBytes(chunks);
}

void WriteMcapBomb(const std::string& path, const std::vector<TestMessage>& messages, const std::string& compression,
                   uint64_t zeros, uint64_t announced_size) {
  // The records as WriteMcap writes them unchunked, then put into one chunk of our own.
  WriteMcap(path, messages, "");
  std::ifstream in(path, std::ios::binary);
  const std::string plain((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string header, records;
  for (size_t at = 8; at + 9 <= plain.size();) {
    const uint8_t op = static_cast<uint8_t>(plain[at]);
    const uint64_t length = Load64(plain, at + 1);
    const std::string content = plain.substr(at + 9, length);
    if (op == 0x01) PutMcapRecord(header, op, content);
    if (op == 0x03 || op == 0x04 || op == 0x05) PutMcapRecord(records, op, content);
    if (op == 0x0F) break;
    at += 9 + length;
  }
  if (zeros > 0) {  // a message on channel 1 (the first topic's), its data the zeros
    std::string head;
    Put16(head, 1);
    Put32(head, 0);
    Put64(head, 0);
    Put64(head, 0);
    records.push_back(0x05);
    Put64(records, head.size() + zeros);
    records += head;
  }
  const std::string stored = CompressedWithZeros(compression, records, zeros);
  std::string chunk;
  Put64(chunk, 0);  // message start and end times: not read
  Put64(chunk, 0);
  Put64(chunk, announced_size ? announced_size : records.size() + zeros);
  Put32(chunk, 0);  // no CRC
  Put32(chunk, static_cast<uint32_t>(compression.size()));
  chunk += compression;
  Put64(chunk, stored.size());
  chunk += stored;
  std::string file("\x89MCAP0\r\n", 8);
  file += header;
  PutMcapRecord(file, 0x06, chunk);
  std::string data_end;
  Put32(data_end, 0);
  PutMcapRecord(file, 0x0F, data_end);
  std::string footer;
  Put64(footer, 0);
  Put64(footer, 0);
  Put32(footer, 0);
  PutMcapRecord(file, 0x02, footer);
  file.append("\x89MCAP0\r\n", 8);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << file;
}

}  // namespace vmap::testing
