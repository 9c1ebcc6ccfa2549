#pragma once
// Test helpers of the tests of docs/promises.md on the binary (cli/*_promises_test.cc): a synthetic input folder, a
// map built from it by the binary, and the entries a run leaves in a folder.

#include <filesystem>
#include <string>
#include <vector>

namespace vmap::testing {

// A folder `directory` of `num_frames` synthetic images (RenderSyntheticSequence, written by WriteImageFolder).
void WriteSyntheticInput(const std::filesystem::path& directory, int num_frames);

// A small real map of `input` at `directory`, built by the binary (`extra`: more arguments of `vmap build`).
void BuildMapWithBinary(const std::filesystem::path& input, const std::filesystem::path& directory,
                        const std::string& extra = "");

// Names in `directory` that start with `prefix`: temporaries left behind.
std::vector<std::string> EntriesStartingWith(const std::filesystem::path& directory, const std::string& prefix);

}  // namespace vmap::testing
