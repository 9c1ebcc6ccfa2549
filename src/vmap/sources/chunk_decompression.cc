#include "vmap/sources/chunk_decompression.h"

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <memory>

namespace vmap {
namespace {

std::string Lz4Frame(const uint8_t* in, size_t size, uint8_t* out, size_t out_size) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) return "cannot start lz4";
  const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> context(raw,
                                                                                     &LZ4F_freeDecompressionContext);
  size_t in_done = 0, out_done = 0;
  for (;;) {
    size_t in_step = size - in_done, out_step = out_size - out_done;
    const size_t hint = LZ4F_decompress(context.get(), out + out_done, &out_step, in + in_done, &in_step, nullptr);
    if (LZ4F_isError(hint)) return std::string("damaged lz4 data (") + LZ4F_getErrorName(hint) + ")";
    in_done += in_step;
    out_done += out_step;
    if (hint == 0) break;  // the frame is complete
    if (in_step == 0 && out_step == 0) {
      return in_done == size ? "lz4 data ends early" : "lz4 data is larger than the chunk's announced size";
    }
  }
  if (out_done != out_size)
    return "lz4 data holds " + std::to_string(out_done) + " bytes, not the announced " + std::to_string(out_size);
  return "";
}

std::string Bz2(const uint8_t* in, size_t size, uint8_t* out, size_t out_size) {
  if (size > UINT_MAX || out_size > UINT_MAX) return "bz2 chunk over 4 GiB";
  unsigned int produced = static_cast<unsigned int>(out_size);
  const int status = BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(out), &produced,
                                                const_cast<char*>(reinterpret_cast<const char*>(in)),
                                                static_cast<unsigned int>(size), 0, 0);
  if (status != BZ_OK) return "damaged bz2 data (bzip2 status " + std::to_string(status) + ")";
  if (produced != out_size)
    return "bz2 data holds " + std::to_string(produced) + " bytes, not the announced " + std::to_string(out_size);
  return "";
}

std::string Zstd(const uint8_t* in, size_t size, uint8_t* out, size_t out_size) {
  const size_t produced = ZSTD_decompress(out, out_size, in, size);
  if (ZSTD_isError(produced)) return std::string("damaged zstd data (") + ZSTD_getErrorName(produced) + ")";
  if (produced != out_size)
    return "zstd data holds " + std::to_string(produced) + " bytes, not the announced " + std::to_string(out_size);
  return "";
}

}  // namespace

std::string DecompressChunk(const std::string& compression, const uint8_t* in, size_t size, uint8_t* out,
                            size_t out_size) {
  if (compression == "lz4") return Lz4Frame(in, size, out, out_size);
  if (compression == "bz2") return Bz2(in, size, out, out_size);
  if (compression == "zstd") return Zstd(in, size, out, out_size);
  return "compression '" + compression + "' is not one vmap reads (lz4, bz2, zstd)";
}

bool StartsWithZstdFrame(const uint8_t* data, size_t size) {
  // ZSTD_MAGICNUMBER, little-endian.
  return size >= 4 && data[0] == 0x28 && data[1] == 0xB5 && data[2] == 0x2F && data[3] == 0xFD;
}

namespace {
using ZstdStream = std::unique_ptr<ZSTD_DStream, decltype(&ZSTD_freeDStream)>;
ZstdStream NewZstdStream() { return ZstdStream(ZSTD_createDStream(), &ZSTD_freeDStream); }
}  // namespace

std::string DecompressZstd(const uint8_t* in, size_t size, size_t max_size, std::vector<uint8_t>* out,
                           bool* too_large) {
  out->clear();
  if (too_large) *too_large = false;
  // A frame that says how much it holds (ZSTD_compress writes it) is refused or sized from that, before any
  // work: grown a piece at a time, the buffer would reach twice the size.
  const unsigned long long announced = ZSTD_getFrameContentSize(in, size);
  if (announced != ZSTD_CONTENTSIZE_UNKNOWN && announced != ZSTD_CONTENTSIZE_ERROR) {
    if (announced > max_size) {
      if (too_large) *too_large = true;
      return "zstd data announces " + std::to_string(announced) + " bytes, more than " + std::to_string(max_size);
    }
    out->reserve(static_cast<size_t>(announced));
  }
  const ZstdStream stream = NewZstdStream();
  if (!stream) return "cannot start zstd";
  ZSTD_inBuffer input{in, size, 0};
  uint8_t piece[1 << 16];
  size_t hint = 1;
  while (input.pos < input.size) {
    ZSTD_outBuffer output{piece, sizeof piece, 0};
    hint = ZSTD_decompressStream(stream.get(), &output, &input);
    if (ZSTD_isError(hint)) return std::string("damaged zstd data (") + ZSTD_getErrorName(hint) + ")";
    if (out->size() + output.pos > max_size) {
      if (too_large) *too_large = true;
      return "zstd data holds more than " + std::to_string(max_size) + " bytes";
    }
    out->insert(out->end(), piece, piece + output.pos);
    if (output.pos == 0 && input.pos == input.size) break;
  }
  // The input is used up; what the decoder still holds comes out now.
  while (hint != 0) {
    ZSTD_outBuffer output{piece, sizeof piece, 0};
    hint = ZSTD_decompressStream(stream.get(), &output, &input);
    if (ZSTD_isError(hint)) return std::string("damaged zstd data (") + ZSTD_getErrorName(hint) + ")";
    if (output.pos == 0) return "zstd data ends early";
    if (out->size() + output.pos > max_size) {
      if (too_large) *too_large = true;
      return "zstd data holds more than " + std::to_string(max_size) + " bytes";
    }
    out->insert(out->end(), piece, piece + output.pos);
  }
  return "";
}

std::string DecompressZstdFile(const ContainedFile& in, const std::string& to, uint64_t max_size) {
  const std::unique_ptr<FILE, decltype(&fclose)> out(fopen(to.c_str(), "wbx"), &fclose);
  if (!out) return "cannot create the decompressed copy '" + to + "'";
  const ZstdStream stream = NewZstdStream();
  if (!stream) return "cannot start zstd";
  std::vector<uint8_t> in_piece(ZSTD_DStreamInSize()), out_piece(ZSTD_DStreamOutSize());
  size_t hint = 1;
  uint64_t read = 0, written = 0;
  while (read < in.size() || hint != 0) {
    const size_t piece = static_cast<size_t>(std::min<uint64_t>(in_piece.size(), in.size() - read));
    if (piece > 0 && !in.Read(read, in_piece.data(), piece)) return "cannot read it";
    read += piece;
    ZSTD_inBuffer input{in_piece.data(), piece, 0};
    // Once the input is used up, what the decoder still holds comes out (one call at least).
    for (bool first = true; first || input.pos < input.size; first = false) {
      ZSTD_outBuffer output{out_piece.data(), out_piece.size(), 0};
      hint = ZSTD_decompressStream(stream.get(), &output, &input);
      if (ZSTD_isError(hint)) return std::string("damaged zstd data (") + ZSTD_getErrorName(hint) + ")";
      if (piece == 0 && output.pos == 0 && hint != 0) return "zstd data ends early";
      written += output.pos;
      if (written > max_size) {
        return "it decompresses to more than " + std::to_string(max_size >> 20) +
               " MiB, more than a recording of its size holds (a decompression bomb, or damage)";
      }
      if (fwrite(out_piece.data(), 1, output.pos, out.get()) != output.pos) {
        return "cannot write the decompressed copy '" + to + "' (disk full?)";
      }
    }
  }
  if (read == 0) return "zstd data ends early";
  if (fflush(out.get()) != 0) return "cannot write the decompressed copy '" + to + "' (disk full?)";
  return "";
}

}  // namespace vmap
