// The LibTorch binaries take libstdc++'s own functions, not the copies some LibTorch builds export
// (CMakeLists.txt: libstdc++ is needed before LibTorch). With PyTorch's LibTorch 2.x the tests crashed in
// std::filesystem::remove_all, resolved inside libtorch.so.
#include <dlfcn.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace vmap {
namespace {

std::string LibraryDefining(const void* address) {
  Dl_info info{};
  if (dladdr(address, &info) == 0 || info.dli_fname == nullptr) return "";
  return info.dli_fname;
}

TEST(LibstdcxxFirst, FilesystemCallsReachLibstdcxx) {
  using RemoveAll = std::uintmax_t (*)(const std::filesystem::path&);
  using Status = std::filesystem::file_status (*)(const std::filesystem::path&);
  const std::string remove_all =
      LibraryDefining(reinterpret_cast<const void*>(static_cast<RemoveAll>(&std::filesystem::remove_all)));
  const std::string status =
      LibraryDefining(reinterpret_cast<const void*>(static_cast<Status>(&std::filesystem::status)));
  EXPECT_NE(remove_all.find("libstdc++"), std::string::npos) << "remove_all comes from " << remove_all;
  EXPECT_NE(status.find("libstdc++"), std::string::npos) << "status comes from " << status;
}

}  // namespace
}  // namespace vmap
