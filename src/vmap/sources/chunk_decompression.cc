#include "vmap/sources/chunk_decompression.h"

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <climits>
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
  if (out_done != out_size) return "lz4 data holds " + std::to_string(out_done) + " bytes, not the announced " +
                                   std::to_string(out_size);
  return "";
}

std::string Bz2(const uint8_t* in, size_t size, uint8_t* out, size_t out_size) {
  if (size > UINT_MAX || out_size > UINT_MAX) return "bz2 chunk over 4 GiB";
  unsigned int produced = static_cast<unsigned int>(out_size);
  const int status = BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(out), &produced,
                                                const_cast<char*>(reinterpret_cast<const char*>(in)),
                                                static_cast<unsigned int>(size), 0, 0);
  if (status != BZ_OK) return "damaged bz2 data (bzip2 status " + std::to_string(status) + ")";
  if (produced != out_size) return "bz2 data holds " + std::to_string(produced) + " bytes, not the announced " +
                                   std::to_string(out_size);
  return "";
}

std::string Zstd(const uint8_t* in, size_t size, uint8_t* out, size_t out_size) {
  const size_t produced = ZSTD_decompress(out, out_size, in, size);
  if (ZSTD_isError(produced)) return std::string("damaged zstd data (") + ZSTD_getErrorName(produced) + ")";
  if (produced != out_size) return "zstd data holds " + std::to_string(produced) + " bytes, not the announced " +
                                   std::to_string(out_size);
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

}  // namespace vmap
