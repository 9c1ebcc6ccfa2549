#include "vmap/neural/checkpoint_reader.h"

#include <cstring>
#include <memory>
#include <stdexcept>
#include <unordered_map>
#include <variant>

#include <caffe2/serialize/inline_container.h>

#include "vmap/core/error.h"

namespace vmap::neural {

namespace {

struct Object;
using Ref = std::shared_ptr<Object>;

// The Python values a checkpoint needs; everything else is kOpaque (a class or instance we do not model).
struct Object {
  enum class Kind { kNone, kBool, kInt, kFloat, kString, kTuple, kList, kDict, kTensor, kGlobal, kOpaque, kMark };
  Kind kind = Kind::kNone;
  int64_t integer = 0;
  double real = 0;
  std::string text;                          // string value, or "module.name" of a global
  std::vector<Ref> items;                    // tuple / list
  std::vector<std::pair<Ref, Ref>> entries;  // dict, in insertion order
  torch::Tensor tensor;
};

Ref Make(Object::Kind kind) {
  auto o = std::make_shared<Object>();
  o->kind = kind;
  return o;
}

torch::ScalarType StorageDtype(const std::string& global) {
  static const std::unordered_map<std::string, torch::ScalarType> types{
      {"torch.FloatStorage", torch::kFloat32},  {"torch.HalfStorage", torch::kFloat16},
      {"torch.DoubleStorage", torch::kFloat64}, {"torch.BFloat16Storage", torch::kBFloat16},
      {"torch.LongStorage", torch::kInt64},     {"torch.IntStorage", torch::kInt32},
      {"torch.ShortStorage", torch::kInt16},    {"torch.CharStorage", torch::kInt8},
      {"torch.ByteStorage", torch::kUInt8},     {"torch.BoolStorage", torch::kBool}};
  auto it = types.find(global);
  if (it == types.end()) throw std::runtime_error("unsupported storage type " + global);
  return it->second;
}

class PickleMachine {
 public:
  PickleMachine(const std::vector<uint8_t>& program, caffe2::serialize::PyTorchStreamReader& archive)
      : code_(program), archive_(archive) {}

  Ref Run() {
    while (true) {
      const uint8_t op = Byte();
      switch (op) {
        case 0x80:
          Byte();
          break;  // PROTO
        case 0x95:
          Skip(8);
          break;  // FRAME
        case '.':
          return Pop();  // STOP
        case '(':
          stack_.push_back(Make(Object::Kind::kMark));
          break;
        case '}':
          stack_.push_back(Make(Object::Kind::kDict));
          break;
        case ']':
          stack_.push_back(Make(Object::Kind::kList));
          break;
        case ')':
          stack_.push_back(Make(Object::Kind::kTuple));
          break;
        case 't': {
          auto t = Make(Object::Kind::kTuple);
          t->items = PopToMark();
          stack_.push_back(t);
          break;
        }
        case 0x85:
        case 0x86:
        case 0x87: {  // TUPLE1..3
          auto t = Make(Object::Kind::kTuple);
          const size_t n = op - 0x84;
          if (stack_.size() < n) throw std::runtime_error("stack underflow");
          t->items.assign(stack_.end() - n, stack_.end());
          stack_.resize(stack_.size() - n);
          stack_.push_back(t);
          break;
        }
        case 'N':
          stack_.push_back(Make(Object::Kind::kNone));
          break;
        case 0x88:
        case 0x89: {
          auto b = Make(Object::Kind::kBool);
          b->integer = op == 0x88;
          stack_.push_back(b);
          break;
        }
        case 'J':
          PushInt(static_cast<int32_t>(Le(4)));
          break;
        case 'K':
          PushInt(static_cast<int64_t>(Le(1)));
          break;
        case 'M':
          PushInt(static_cast<int64_t>(Le(2)));
          break;
        case 0x8a: {  // LONG1: little-endian two's complement
          const size_t n = Byte();
          uint64_t v = 0;
          for (size_t i = 0; i < n; ++i) v |= uint64_t(Byte()) << (8 * i);
          if (n > 0 && n < 8 && (v >> (8 * n - 1)) & 1) v |= ~uint64_t(0) << (8 * n);
          PushInt(static_cast<int64_t>(v));
          break;
        }
        case 'G': {  // BINFLOAT, big-endian
          uint64_t bits = 0;
          for (int i = 0; i < 8; ++i) bits = (bits << 8) | Byte();
          auto f = Make(Object::Kind::kFloat);
          std::memcpy(&f->real, &bits, 8);
          stack_.push_back(f);
          break;
        }
        case 'X':
          PushString(Le(4));
          break;  // BINUNICODE
        case 0x8c:
          PushString(Byte());
          break;  // SHORT_BINUNICODE
        case 'T':
          PushString(Le(4));
          break;  // BINSTRING
        case 'U':
          PushString(Byte());
          break;  // SHORT_BINSTRING
        case 'B':
          PushString(Le(4));
          break;  // BINBYTES
        case 'C':
          PushString(Byte());
          break;  // SHORT_BINBYTES
        case 'q':
          memo_[Byte()] = Top();
          break;  // BINPUT
        case 'r':
          memo_[Le(4)] = Top();
          break;  // LONG_BINPUT
        case 0x94:
          memo_[memo_.size()] = Top();
          break;  // MEMOIZE
        case 'h':
          stack_.push_back(Memo(Byte()));
          break;
        case 'j':
          stack_.push_back(Memo(Le(4)));
          break;
        case 'c': {  // GLOBAL module\nname\n
          const std::string module = Line(), name = Line();
          auto g = Make(Object::Kind::kGlobal);
          g->text = module + "." + name;
          stack_.push_back(g);
          break;
        }
        case 0x93: {  // STACK_GLOBAL
          auto name = Pop(), module = Pop();
          auto g = Make(Object::Kind::kGlobal);
          g->text = module->text + "." + name->text;
          stack_.push_back(g);
          break;
        }
        case 'R': {
          auto args = Pop();
          auto callable = Pop();
          stack_.push_back(Call(callable, args));
          break;
        }
        case 0x81: {
          Pop();
          Pop();
          stack_.push_back(Make(Object::Kind::kOpaque));
          break;
        }  // NEWOBJ
        case 'b':
          Pop();
          break;  // BUILD: object state (attributes) is not needed
        case 'Q':
          stack_.push_back(Persistent(Pop()));
          break;
        case 's': {
          auto v = Pop();
          auto k = Pop();
          SetItem(Top(), k, v);
          break;
        }
        case 'u': {
          auto items = PopToMark();
          for (size_t i = 0; i + 1 < items.size(); i += 2) SetItem(Top(), items[i], items[i + 1]);
          break;
        }
        case 'a': {
          auto v = Pop();
          Append(Top(), v);
          break;
        }
        case 'e': {
          for (auto& v : PopToMark()) Append(Top(), v);
          break;
        }
        case '0':
          Pop();
          break;
        case '1':
          PopToMark();
          break;
        case '2':
          stack_.push_back(Top());
          break;
        default: {
          char hex[8];
          std::snprintf(hex, sizeof(hex), "0x%02x", op);
          throw std::runtime_error(std::string("unsupported pickle opcode ") + hex);
        }
      }
    }
  }

 private:
  uint8_t Byte() {
    if (pos_ >= code_.size()) throw std::runtime_error("pickle program ends early");
    return code_[pos_++];
  }
  void Skip(size_t n) {
    for (size_t i = 0; i < n; ++i) Byte();
  }
  uint64_t Le(int n) {
    uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= uint64_t(Byte()) << (8 * i);
    return v;
  }
  std::string Line() {
    std::string s;
    for (char c; (c = static_cast<char>(Byte())) != '\n';) s += c;
    return s;
  }
  void PushInt(int64_t v) {
    auto i = Make(Object::Kind::kInt);
    i->integer = v;
    stack_.push_back(i);
  }
  void PushString(uint64_t n) {
    if (n > code_.size() - pos_) throw std::runtime_error("string past the end of the pickle");
    auto s = Make(Object::Kind::kString);
    s->text.assign(reinterpret_cast<const char*>(code_.data() + pos_), n);
    pos_ += n;
    stack_.push_back(s);
  }
  Ref Pop() {
    if (stack_.empty()) throw std::runtime_error("stack underflow");
    auto v = stack_.back();
    stack_.pop_back();
    return v;
  }
  Ref& Top() {
    if (stack_.empty()) throw std::runtime_error("stack underflow");
    return stack_.back();
  }
  Ref Memo(uint64_t id) {
    auto it = memo_.find(id);
    if (it == memo_.end()) throw std::runtime_error("unknown memo entry");
    return it->second;
  }
  std::vector<Ref> PopToMark() {
    for (size_t i = stack_.size(); i-- > 0;) {
      if (stack_[i]->kind == Object::Kind::kMark) {
        std::vector<Ref> items(stack_.begin() + static_cast<std::ptrdiff_t>(i) + 1, stack_.end());
        stack_.resize(i);
        return items;
      }
    }
    throw std::runtime_error("no mark on the stack");
  }
  static void SetItem(const Ref& target, const Ref& key, const Ref& value) {
    if (target->kind == Object::Kind::kDict) target->entries.emplace_back(key, value);
  }
  static void Append(const Ref& target, const Ref& value) {
    if (target->kind == Object::Kind::kList) target->items.push_back(value);
  }

  // ('storage', storage class, key, location, numel): the raw bytes of record data/<key>.
  Ref Persistent(const Ref& id) {
    if (id->kind != Object::Kind::kTuple || id->items.size() < 5 || id->items[0]->text != "storage") {
      throw std::runtime_error("unsupported persistent id");
    }
    const torch::ScalarType dtype = StorageDtype(id->items[1]->text);
    const std::string key = id->items[2]->text;
    const int64_t numel = id->items[4]->integer;
    auto cached = storages_.find(key);
    if (cached != storages_.end()) return cached->second;
    auto [data, size] = archive_.getRecord("data/" + key);
    const size_t needed = static_cast<size_t>(numel) * c10::elementSize(dtype);
    if (size < needed) throw std::runtime_error("record data/" + key + " is shorter than its tensor");
    auto storage = Make(Object::Kind::kTensor);
    storage->tensor = torch::empty({numel}, torch::TensorOptions().dtype(dtype));
    std::memcpy(storage->tensor.data_ptr(), data.get(), needed);
    storages_[key] = storage;
    return storage;
  }

  static std::vector<int64_t> Ints(const Ref& tuple) {
    std::vector<int64_t> v;
    for (const auto& item : tuple->items) v.push_back(item->integer);
    return v;
  }

  Ref Call(const Ref& callable, const Ref& args) {
    const std::string& name = callable->kind == Object::Kind::kGlobal ? callable->text : std::string();
    if (name == "collections.OrderedDict") return Make(Object::Kind::kDict);
    if (name == "torch._utils._rebuild_tensor_v2" || name == "torch._utils._rebuild_tensor") {
      if (args->items.size() < 4 || args->items[0]->kind != Object::Kind::kTensor) {
        throw std::runtime_error("malformed tensor record");
      }
      auto t = Make(Object::Kind::kTensor);
      t->tensor = args->items[0]
                      ->tensor.as_strided(Ints(args->items[2]), Ints(args->items[3]), args->items[1]->integer)
                      .clone();
      return t;
    }
    if (name == "torch._utils._rebuild_parameter" && !args->items.empty()) return args->items[0];
    return Make(Object::Kind::kOpaque);
  }

  const std::vector<uint8_t>& code_;
  caffe2::serialize::PyTorchStreamReader& archive_;
  size_t pos_ = 0;
  std::vector<Ref> stack_;
  std::unordered_map<uint64_t, Ref> memo_;
  std::unordered_map<std::string, Ref> storages_;
};

const Object* Lookup(const Object& dict, const std::string& key) {
  for (const auto& [k, v] : dict.entries) {
    if (k->kind == Object::Kind::kString && k->text == key) return v.get();
  }
  return nullptr;
}

}  // namespace

StateDict ReadCheckpointTensors(const std::string& path) {
  std::unique_ptr<caffe2::serialize::PyTorchStreamReader> archive;
  try {
    archive = std::make_unique<caffe2::serialize::PyTorchStreamReader>(path);
  } catch (const c10::Error& e) {
    throw std::runtime_error("not a torch.save zip archive");
  }
  auto [data, size] = archive->getRecord("data.pkl");
  const auto* bytes = static_cast<const uint8_t*>(data.get());
  const std::vector<uint8_t> program(bytes, bytes + size);
  const Ref root = PickleMachine(program, *archive).Run();
  if (root->kind != Object::Kind::kDict) throw std::runtime_error("the file does not hold a dict");
  const Object* tensors = root.get();
  for (const char* nested : {"state_dict", "model_state_dict"}) {
    if (const Object* inner = Lookup(*root, nested); inner && inner->kind == Object::Kind::kDict) {
      tensors = inner;
      break;
    }
  }
  StateDict out;
  for (const auto& [k, v] : tensors->entries) {
    if (k->kind == Object::Kind::kString && v->kind == Object::Kind::kTensor) out[k->text] = v->tensor;
  }
  return out;
}

StateDict ReadRefusedWeightsFile(const std::string& path, const std::string& model, const std::string& first_error,
                                 size_t file_size) {
  try {
    return ReadCheckpointTensors(path);
  } catch (const std::exception& e) {
    throw InputError("cannot read " + model + " weights file '" + path + "' (" + std::to_string(file_size) +
                     " bytes): it is not a complete torch.save zip archive (" + first_error + "; " + e.what() +
                     "). Get the file again (see `vmap weights`)");
  }
}

}  // namespace vmap::neural
