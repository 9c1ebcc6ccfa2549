// libFuzzer target: JSON as vmap parses the files it did not write (map.json, a run's JSON, eval.json):
// ContainedFile::ParseJson with its bounds on values and nesting; then printed again, as map.json's options
// are.
#include "vmap/core/contained_file.h"

#include "recording_fuzzer.h"  // Scratch()

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& folder = vmap::fuzz::Scratch();
  std::ofstream(folder + "/map.json", std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  const vmap::ContainedJson parsed = vmap::ReadContainedJson(folder, "map.json", 1 << 20, 1 << 16);
  if (parsed.document) (void)parsed.document->dump(1);
  return 0;
}
