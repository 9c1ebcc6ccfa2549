// libFuzzer target: a mcap file (.mcap) as vmap reads it (recording_fuzzer.h).
#include "recording_fuzzer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return vmap::fuzz::FuzzRecording(data, size, ".mcap");
}
