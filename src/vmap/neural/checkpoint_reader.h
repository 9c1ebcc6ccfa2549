#pragma once
// A reader for `torch.save` zip files that LibTorch's own unpickler rejects: PyTorch-Lightning checkpoints
// such as the official LoFTR outdoor_ds.ckpt hold their state dict as a collections.OrderedDict (LibTorch
// turns it into None) next to training metadata of arbitrary Python classes. This reader runs the pickle
// program itself, keeps dicts, lists, tuples, scalars and tensors, and treats any other object as opaque.
// Includes LibTorch: internal to vmap/neural.

#include <string>
#include <vector>

#include "vmap/neural/state_dict.h"

namespace vmap::neural {

// Every tensor of the checkpoint's "state_dict" (else "model_state_dict", else the top-level dict),
// keyed as stored. Throws std::runtime_error describing the first problem (not a zip, unsupported opcode,
// missing record...).
StateDict ReadCheckpointTensors(const std::string& path);

// ReadCheckpointTensors for a weights file of `model` ("LoFTR", "XFeat", "ALIKED") that LibTorch's unpickler
// refused with `first_error`. Throws InputError naming the file and both reasons when it is not a readable
// torch.save archive either.
StateDict ReadRefusedWeightsFile(const std::string& path, const std::string& model, const std::string& first_error,
                                 size_t file_size);

}  // namespace vmap::neural
