#include "penumbra/control/onnx_model_check.h"

#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// ONNX TensorProto.DataType values the checker accepts
constexpr int kFloat = 1;
constexpr int kInt64 = 7;
constexpr int kMaxRank = 8;
constexpr int kMaxShapeValues = 8;  // a Reshape's shape tensor
constexpr int64_t kMaxNodeInputs = 1024;
constexpr int64_t kMaxNodeAttributes = 64;

const char* const kUnary[] = {"Relu",        "LeakyRelu", "Elu",      "Selu",    "Tanh", "Sigmoid",
                              "HardSigmoid", "Softplus",  "Softsign", "Abs",     "Neg",  "Exp",
                              "Sqrt",        "Identity",  "Softmax",  "Dropout", "Clip"};
const char* const kBinary[] = {"Add", "Sub", "Mul", "Div"};
const char* const kOther[] = {"MatMul", "Gemm", "Flatten", "Reshape", "Concat", "Constant"};

bool In(const std::string& op, const auto& list) {
  for (const char* s : list)
    if (op == s) return true;
  return false;
}

// one protobuf field
struct Field {
  uint32_t number = 0;
  int wire = 0;
  uint64_t value = 0;      // varint, fixed32 or fixed64
  std::string_view bytes;  // length-delimited
  size_t offset = 0;       // of its tag in the file
};

struct Attribute {
  std::string name;
  std::optional<int64_t> i;
  std::optional<float> f;
  std::string_view tensor;  // the `t` field
};

struct Value {
  std::vector<int64_t> shape;
  int dtype = kFloat;
  bool constant = false;
  std::vector<int64_t> ints;  // a small int64 constant's values
};

std::string Join(const std::vector<int64_t>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
  return s + "]";
}

class Checker {
 public:
  Checker(std::string_view file, const std::string& path, int in, int out)
      : file_(file), path_(path), in_(in), out_(out) {}

  OnnxModelSummary Run() {
    if (static_cast<int64_t>(file_.size()) > kOnnxMaxFileBytes)
      Fail("the file has " + std::to_string(file_.size()) + " bytes; expected at most " +
           std::to_string(kOnnxMaxFileBytes) + " (kOnnxMaxFileBytes)");
    if (file_.empty()) Fail("the file is empty; expected an ONNX model");
    std::string_view graph;
    bool have_ir = false, have_graph = false;
    std::vector<std::string_view> opsets;
    ForEach(file_, "ModelProto", [&](const Field& f) {
      switch (f.number) {
        case 1:
          summary_.ir_version = static_cast<int64_t>(Varint(f, "ModelProto.ir_version"));
          have_ir = true;
          break;
        case 7:
          if (have_graph) FailAt(f, "ModelProto has two graphs; expected one");
          graph = Bytes(f, "ModelProto.graph");
          have_graph = true;
          break;
        case 8:
          opsets.push_back(Bytes(f, "ModelProto.opset_import"));
          break;
        case 20:
          Fail("the model has training_info; expected an inference-only model");
        case 25:
          Fail("the model defines functions; expected only the standard operators (" +
               OnnxSupportedOperators() + ")");
        default:
          break;
      }
    });
    if (!have_ir) Fail("the model has no ir_version; expected an ONNX model (IR 3 .. 10)");
    if (summary_.ir_version < 3 || summary_.ir_version > 10)
      Fail("IR version " + std::to_string(summary_.ir_version) + "; expected 3 .. 10");
    if (!have_graph) Fail("the model has no graph; expected an ONNX model");
    for (std::string_view o : opsets) {
      std::string domain;
      std::optional<int64_t> version;
      ForEach(o, "OperatorSetIdProto", [&](const Field& f) {
        if (f.number == 1) domain = Str(f, "opset_import.domain");
        if (f.number == 2) version = static_cast<int64_t>(Varint(f, "opset_import.version"));
      });
      if (domain != "" && domain != "ai.onnx")
        Fail("opset_import of domain '" + Quote(domain) +
             "'; expected only the default ONNX domain (operators: " + OnnxSupportedOperators() +
             ")");
      if (summary_.opset != 0) Fail("two opset_import entries of the default domain; expected one");
      if (!version || *version < kOnnxMinOpset || *version > kOnnxMaxOpset)
        Fail("opset " + (version ? std::to_string(*version) : std::string("(none)")) +
             "; expected an opset of " + std::to_string(kOnnxMinOpset) + " .. " +
             std::to_string(kOnnxMaxOpset) + " (what OpenCV 4.6 dnn imports)");
      summary_.opset = *version;
    }
    if (summary_.opset == 0)
      Fail("the model imports no opset of the default domain; expected one of " +
           std::to_string(kOnnxMinOpset) + " .. " + std::to_string(kOnnxMaxOpset));
    Graph(graph);
    return summary_;
  }

 private:
  [[noreturn]] void Fail(const std::string& problem) const {
    throw ConfigError(path_, 0, "", problem);
  }
  [[noreturn]] void FailAt(const Field& f, const std::string& problem) const {
    Fail("at byte " + std::to_string(f.offset) + ": " + problem);
  }
  [[noreturn]] void Malformed(const char* p, const std::string& what) const {
    Fail("not a valid ONNX (protobuf) file: " + what + " at byte " +
         std::to_string(p - file_.data()));
  }
  static std::string Quote(std::string_view s) { return SanitizeForMessage(s, 80); }

  // reads a varint at p (< end), advancing p
  uint64_t ReadVarint(const char*& p, const char* end) const {
    uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (p >= end) Malformed(p, "a truncated varint");
      const uint8_t b = static_cast<uint8_t>(*p++);
      if (shift == 63 && b > 1) Malformed(p - 1, "a varint longer than 64 bits");
      v |= static_cast<uint64_t>(b & 0x7f) << shift;
      if (!(b & 0x80)) return v;
    }
    Malformed(p, "a varint longer than 10 bytes");
  }

  // calls fn(field) for each field of the message `msg`
  template <class Fn>
  void ForEach(std::string_view msg, const char* type, Fn&& fn) const {
    const char* p = msg.data();
    const char* end = p + msg.size();
    while (p < end) {
      Field f;
      f.offset = static_cast<size_t>(p - file_.data());
      const uint64_t tag = ReadVarint(p, end);
      f.number = static_cast<uint32_t>(tag >> 3);
      f.wire = static_cast<int>(tag & 7);
      if (tag >> 3 == 0 || tag >> 3 > 536870911u)
        Malformed(p, std::string("a field number of 0 or > 2^29 in ") + type);
      switch (f.wire) {
        case 0:
          f.value = ReadVarint(p, end);
          break;
        case 1:
          if (end - p < 8) Malformed(p, std::string("a truncated 64-bit field in ") + type);
          std::memcpy(&f.value, p, 8);
          p += 8;
          break;
        case 5: {
          if (end - p < 4) Malformed(p, std::string("a truncated 32-bit field in ") + type);
          uint32_t v;
          std::memcpy(&v, p, 4);
          f.value = v;
          p += 4;
          break;
        }
        case 2: {
          const uint64_t len = ReadVarint(p, end);
          if (len > static_cast<uint64_t>(end - p))
            Malformed(p, "a length of " + std::to_string(len) + " past the end of its " + type);
          f.bytes = std::string_view(p, len);
          p += len;
          break;
        }
        default:
          Malformed(p, "wire type " + std::to_string(f.wire) +
                           " (groups are not used by ONNX) in " + type);
      }
      fn(f);
    }
  }

  uint64_t Varint(const Field& f, const char* what) const {
    if (f.wire != 0) FailAt(f, std::string(what) + " is not a varint; expected an integer");
    return f.value;
  }
  std::string_view Bytes(const Field& f, const char* what) const {
    if (f.wire != 2) FailAt(f, std::string(what) + " is not length-delimited");
    return f.bytes;
  }
  std::string Str(const Field& f, const char* what) const {
    const std::string_view b = Bytes(f, what);
    if (b.size() > 4096)
      FailAt(f, std::string(what) + " has " + std::to_string(b.size()) +
                    " bytes; expected a name of at most 4096");
    return std::string(b);
  }

  // number of varints in a packed field
  int64_t CountVarints(const Field& f) const {
    const char* p = f.bytes.data();
    const char* end = p + f.bytes.size();
    int64_t n = 0;
    while (p < end) {
      ReadVarint(p, end);
      ++n;
    }
    return n;
  }

  // a repeated int64 field (packed or not) appended to `out`, at most `max` values
  void Int64s(const Field& f, std::vector<int64_t>* out, size_t max, const std::string& what) {
    auto push = [&](uint64_t v) {
      if (out->size() >= max) FailAt(f, what + " has more than " + std::to_string(max) + " values");
      out->push_back(static_cast<int64_t>(v));
    };
    if (f.wire == 0) {
      push(f.value);
    } else if (f.wire == 2) {
      const char* p = f.bytes.data();
      const char* end = p + f.bytes.size();
      while (p < end) push(ReadVarint(p, end));
    } else {
      FailAt(f, what + " is not a list of integers");
    }
  }

  // element count of `dims`, each >= 1, at most `cap`
  int64_t Elements(const std::vector<int64_t>& dims, int64_t cap, const std::string& what,
                   const char* cap_name) const {
    int64_t n = 1;
    for (int64_t d : dims) {
      if (d < 1) Fail(what + " has dims " + Join(dims) + "; expected every dim >= 1");
      if (n > cap / d)
        Fail(what + " has dims " + Join(dims) + ": more than " + std::to_string(cap) +
             " elements (" + cap_name + ")");
      n *= d;
    }
    if (n > cap)
      Fail(what + " has dims " + Join(dims) + ": more than " + std::to_string(cap) + " elements (" +
           cap_name + ")");
    return n;
  }

  // checks one TensorProto (an initializer or a Constant's value) and returns its value
  Value Tensor(std::string_view msg, const std::string& where, std::string* name) {
    Value v;
    std::vector<int64_t> dims;
    std::optional<int> dtype;
    int64_t typed_float = 0, typed_int64 = 0;
    std::optional<std::string_view> raw;
    std::vector<int64_t> int64_values;
    ForEach(msg, "TensorProto", [&](const Field& f) {
      switch (f.number) {
        case 1:
          Int64s(f, &dims, kMaxRank, where + " dims");
          break;
        case 2:
          dtype = static_cast<int>(Varint(f, "TensorProto.data_type"));
          break;
        case 3:
          Fail(where + " is segmented; expected a whole tensor");
        case 4:  // float_data
          if (f.wire == 5)
            ++typed_float;
          else if (f.wire == 2 && f.bytes.size() % 4 == 0)
            typed_float += static_cast<int64_t>(f.bytes.size() / 4);
          else
            FailAt(f, where + " float_data is not a list of 32-bit floats");
          break;
        case 7:  // int64_data
          if (f.wire == 0) {
            ++typed_int64;
            if (int64_values.size() < kMaxShapeValues)
              int64_values.push_back(static_cast<int64_t>(f.value));
          } else if (f.wire == 2) {
            const int64_t n = CountVarints(f);
            if (typed_int64 + n <= kMaxShapeValues)
              Int64s(f, &int64_values, kMaxShapeValues, where);
            typed_int64 += n;
          } else {
            FailAt(f, where + " int64_data is not a list of integers");
          }
          break;
        case 8:
          if (name) *name = Str(f, "TensorProto.name");
          break;
        case 9:
          if (raw) FailAt(f, where + " has two raw_data fields; expected one");
          raw = Bytes(f, "TensorProto.raw_data");
          break;
        case 13:
        case 14:
          Fail(where + " uses external data; expected its data inside the ONNX file");
        case 5:
        case 6:
        case 10:
        case 11:
          Fail(where +
               " holds int32, string, double or uint64 data; expected float32 weights "
               "(or int64 Reshape shapes)");
        default:
          break;
      }
    });
    const std::string label = name && !name->empty() ? where + " '" + Quote(*name) + "'" : where;
    if (!dtype) Fail(label + " has no data_type; expected float32 (1) or int64 (7)");
    if (*dtype != kFloat && *dtype != kInt64)
      Fail(label + " has data type " + std::to_string(*dtype) +
           "; expected float32 (1) or int64 (7, for Reshape shapes)");
    const int64_t n = Elements(dims, kOnnxMaxTensorElements, label, "kOnnxMaxTensorElements");
    const int64_t elem = *dtype == kFloat ? 4 : 8;
    const int64_t typed = *dtype == kFloat ? typed_float : typed_int64;
    if ((*dtype == kFloat && typed_int64) || (*dtype == kInt64 && typed_float))
      Fail(label + " holds values of another type than its data_type " + std::to_string(*dtype));
    if (raw && typed) Fail(label + " has both raw_data and typed values; expected one of them");
    if (raw) {
      if (static_cast<int64_t>(raw->size()) != n * elem)
        Fail(label + " has dims " + Join(dims) + " (" + std::to_string(n) + " elements, " +
             std::to_string(n * elem) + " bytes) but its raw_data holds " +
             std::to_string(raw->size()) + " bytes; expected exactly " + std::to_string(n * elem));
      if (*dtype == kInt64 && n <= kMaxShapeValues) {
        int64_values.assign(n, 0);
        std::memcpy(int64_values.data(), raw->data(), n * 8);  // little-endian, as ONNX's
      }
    } else if (typed != n) {
      Fail(label + " has dims " + Join(dims) + " (" + std::to_string(n) + " elements) but holds " +
           std::to_string(typed) + " " + (*dtype == kFloat ? "float_data" : "int64_data") +
           " values; expected exactly " + std::to_string(n));
    }
    weight_bytes_ += n * elem;
    if (weight_bytes_ > kOnnxMaxWeightBytes)
      Fail(label + " brings the model's tensors to more than " +
           std::to_string(kOnnxMaxWeightBytes) + " bytes (kOnnxMaxWeightBytes)");
    v.shape = dims;
    v.dtype = *dtype;
    v.constant = true;
    if (*dtype == kInt64 && n <= kMaxShapeValues) v.ints = int64_values;
    return v;
  }

  // a ValueInfoProto's name and shape (dims; -1 for a symbolic or unknown dim)
  void ValueInfo(std::string_view msg, const char* where, std::string* name,
                 std::optional<std::vector<int64_t>>* shape) {
    std::string_view type;
    bool have_type = false;
    ForEach(msg, "ValueInfoProto", [&](const Field& f) {
      if (f.number == 1) *name = Str(f, "ValueInfoProto.name");
      if (f.number == 2) {
        if (have_type) FailAt(f, std::string(where) + " has two types");
        type = Bytes(f, "ValueInfoProto.type");
        have_type = true;
      }
    });
    const std::string label = std::string(where) + " '" + Quote(*name) + "'";
    if (!have_type) Fail(label + " has no type; expected a float32 tensor");
    std::string_view tensor_type;
    bool have_tensor = false;
    ForEach(type, "TypeProto", [&](const Field& f) {
      if (f.number == 1) {
        if (have_tensor) FailAt(f, label + " has two tensor types");
        tensor_type = Bytes(f, "TypeProto.tensor_type");
        have_tensor = true;
      } else if (f.number != 6) {
        Fail(label + " is a sequence, map, optional or sparse value; expected a float32 tensor");
      }
    });
    if (!have_tensor) Fail(label + " is not a tensor; expected a float32 tensor");
    std::optional<int64_t> elem;
    std::string_view shape_msg;
    bool have_shape = false;
    ForEach(tensor_type, "TypeProto.Tensor", [&](const Field& f) {
      if (f.number == 1) elem = static_cast<int64_t>(Varint(f, "elem_type"));
      if (f.number == 2) {
        if (have_shape) FailAt(f, label + " has two shapes");
        shape_msg = Bytes(f, "TypeProto.Tensor.shape");
        have_shape = true;
      }
    });
    if (elem != kFloat)
      Fail(label + " has element type " + (elem ? std::to_string(*elem) : std::string("(none)")) +
           "; expected float32 (1)");
    if (!have_shape) return;
    std::vector<int64_t> dims;
    ForEach(shape_msg, "TensorShapeProto", [&](const Field& f) {
      if (f.number != 1) return;
      if (dims.size() >= kMaxRank)
        Fail(label + " has more than " + std::to_string(kMaxRank) + " dims");
      int64_t d = -1;
      ForEach(Bytes(f, "TensorShapeProto.dim"), "Dimension", [&](const Field& g) {
        if (g.number == 1) {
          d = static_cast<int64_t>(Varint(g, "dim_value"));
          if (d < 0) Fail(label + " has a negative dim " + std::to_string(d));
        }
      });
      dims.push_back(d);
    });
    *shape = dims;
  }

  void Graph(std::string_view graph) {
    std::vector<std::string_view> nodes, inits, inputs, outputs;
    ForEach(graph, "GraphProto", [&](const Field& f) {
      switch (f.number) {
        case 1:
          if (static_cast<int64_t>(nodes.size()) >= kOnnxMaxNodes)
            Fail("the graph has more than " + std::to_string(kOnnxMaxNodes) +
                 " nodes (kOnnxMaxNodes)");
          nodes.push_back(Bytes(f, "GraphProto.node"));
          break;
        case 5:
          inits.push_back(Bytes(f, "GraphProto.initializer"));
          break;
        case 11:
          inputs.push_back(Bytes(f, "GraphProto.input"));
          break;
        case 12:
          outputs.push_back(Bytes(f, "GraphProto.output"));
          break;
        case 15:
          Fail("the graph has sparse initializers; expected dense float32 tensors");
        default:
          break;
      }
    });
    // the operators first: an unsupported one is the most useful refusal
    for (size_t i = 0; i < nodes.size(); ++i) {
      std::string name, op, domain;
      ForEach(nodes[i], "NodeProto", [&](const Field& f) {
        if (f.number == 3) name = Str(f, "NodeProto.name");
        if (f.number == 4) op = Str(f, "NodeProto.op_type");
        if (f.number == 7) domain = Str(f, "NodeProto.domain");
      });
      CheckOperator(i, name, op, domain);
    }
    for (size_t i = 0; i < inits.size(); ++i) {
      std::string name;
      Value v = Tensor(inits[i], "initializer " + std::to_string(i), &name);
      if (name.empty()) Fail("initializer " + std::to_string(i) + " has no name");
      if (!values_.emplace(name, std::move(v)).second)
        Fail("two initializers are named '" + Quote(name) + "'; expected unique names");
    }
    // the one input that is not an initializer
    for (std::string_view in : inputs) {
      std::string name;
      std::optional<std::vector<int64_t>> shape;
      ValueInfo(in, "graph input", &name, &shape);
      if (values_.count(name) && values_[name].constant) continue;
      if (!summary_.input_name.empty())
        Fail("the graph has inputs '" + Quote(summary_.input_name) + "' and '" + Quote(name) +
             "'; expected one observation input");
      summary_.input_name = name;
      const std::string expected =
          "expected [1, " + std::to_string(in_) + "] (the configured observation size)";
      if (!shape) Fail("graph input '" + Quote(name) + "' declares no shape; " + expected);
      const auto& s = *shape;
      const bool ok = (s.size() == 2 && (s[0] == 1 || s[0] == -1) && s[1] == in_) ||
                      (s.size() == 1 && s[0] == in_);
      if (!ok) {
        std::vector<int64_t> shown = s;
        Fail("graph input '" + Quote(name) + "' has shape " + Join(shown) + " (-1: symbolic); " +
             expected);
      }
      values_[name] = Value{{1, in_}, kFloat, false, {}};
    }
    if (summary_.input_name.empty())
      Fail(
          "the graph has no input besides its initializers; expected one observation input of "
          "[1, " +
          std::to_string(in_) + "]");
    if (outputs.size() != 1)
      Fail("the graph has " + std::to_string(outputs.size()) +
           " outputs; expected one action output of " + std::to_string(out_) + " values");
    std::optional<std::vector<int64_t>> out_shape;
    ValueInfo(outputs[0], "graph output", &summary_.output_name, &out_shape);
    if (out_shape) {
      // -1 (symbolic) dims count as 1 (the batch)
      int64_t n = 1;
      bool ok = true;
      for (int64_t d : *out_shape) {
        if (d == 0 || d > out_) ok = false;
        if (ok && d > 0) n *= d;  // both <= out_: no overflow
        if (n > out_) ok = false;
      }
      if (!ok || n != out_)
        Fail("graph output '" + Quote(summary_.output_name) + "' declares shape " +
             Join(*out_shape) + "; expected " + std::to_string(out_) +
             " values (one per policy joint)");
    }
    if (nodes.empty()) Fail("the graph has no nodes; expected a network");
    for (size_t i = 0; i < nodes.size(); ++i) Node(nodes[i], i);
    summary_.nodes = static_cast<int64_t>(nodes.size());
    summary_.weight_bytes = weight_bytes_;
    auto it = values_.find(summary_.output_name);
    if (it == values_.end() || it->second.constant)
      Fail("graph output '" + Quote(summary_.output_name) +
           "' is not computed by any node; expected the network's action output");
    summary_.output_shape = it->second.shape;
    summary_.input_shape = {1, in_};
    int64_t n = 1;
    for (int64_t d : it->second.shape) n *= d;  // bounded by kOnnxMaxActivationElements
    if (n != out_)
      Fail("the graph computes " + Join(it->second.shape) + " (" + std::to_string(n) +
           " values) at its output '" + Quote(summary_.output_name) + "' for an input of [1, " +
           std::to_string(in_) + "]; expected " + std::to_string(out_) +
           " values (one per policy joint)");
  }

  void Node(std::string_view msg, size_t index) {
    std::vector<std::string> ins, outs;
    std::string name, op, domain;
    std::vector<Attribute> attrs;
    ForEach(msg, "NodeProto", [&](const Field& f) {
      switch (f.number) {
        case 1:
          if (static_cast<int64_t>(ins.size()) >= kMaxNodeInputs)
            FailAt(f, "a node with more than " + std::to_string(kMaxNodeInputs) + " inputs");
          ins.push_back(Str(f, "NodeProto.input"));
          break;
        case 2:
          if (outs.size() >= 8) FailAt(f, "a node with more than 8 outputs");
          outs.push_back(Str(f, "NodeProto.output"));
          break;
        case 3:
          name = Str(f, "NodeProto.name");
          break;
        case 4:
          op = Str(f, "NodeProto.op_type");
          break;
        case 7:
          domain = Str(f, "NodeProto.domain");
          break;
        case 5:
          if (static_cast<int64_t>(attrs.size()) >= kMaxNodeAttributes)
            FailAt(f,
                   "a node with more than " + std::to_string(kMaxNodeAttributes) + " attributes");
          attrs.push_back(Attr(Bytes(f, "NodeProto.attribute"), index));
          break;
        default:
          break;
      }
    });
    const std::string label =
        "node " + std::to_string(index) + " '" + Quote(name) + "' (" + Quote(op) + ")";
    CheckOperator(index, name, op, domain);
    for (const Attribute& a : attrs)
      if (!a.tensor.empty() && op != "Constant")
        Fail(label + " has a tensor attribute '" + Quote(a.name) + "'; expected none");
    auto attr = [&](const char* n) -> const Attribute* {
      for (const Attribute& a : attrs)
        if (a.name == n) return &a;
      return nullptr;
    };
    auto int_attr = [&](const char* n, int64_t def) {
      const Attribute* a = attr(n);
      return a && a->i ? *a->i : def;
    };
    // inputs: defined before this node ("" = an omitted optional input)
    std::vector<const Value*> in;
    for (const std::string& s : ins) {
      if (s.empty()) {
        in.push_back(nullptr);
        continue;
      }
      auto it = values_.find(s);
      if (it == values_.end())
        Fail(label + " reads '" + Quote(s) +
             "', which no earlier node, initializer or input defines; expected nodes in "
             "topological order");
      in.push_back(&it->second);
    }
    // the first `lo` inputs are required: none of them may be omitted ("")
    auto need = [&](size_t lo, size_t hi) {
      if (in.size() < lo || in.size() > hi)
        Fail(label + " has " + std::to_string(in.size()) + " inputs; expected " +
             std::to_string(lo) + (hi != lo ? " .. " + std::to_string(hi) : ""));
      for (size_t i = 0; i < lo; ++i)
        if (!in[i])
          Fail(label + " omits its required input " + std::to_string(i) +
               "; expected a tensor name");
    };
    auto need_float = [&](size_t i) {
      if (i < in.size() && in[i] && in[i]->dtype != kFloat)
        Fail(label + " input " + std::to_string(i) + " '" + Quote(ins[i]) +
             "' is not float32; expected float32");
    };
    if (outs.size() != 1 || outs[0].empty())
      Fail(label + " has " + std::to_string(outs.size()) + " outputs; expected one");
    for (size_t i = 0; i < in.size(); ++i)
      if (op != "Reshape" || i == 0) need_float(i);

    Value out;
    const std::string what = label + " output '" + Quote(outs[0]) + "'";
    if (op == "Constant") {
      need(0, 0);
      const Attribute* v = attr("value");
      if (!v || v->tensor.empty() || attrs.size() != 1)
        Fail(label + " has no `value` tensor (or other attributes); expected one `value` tensor");
      out = Tensor(v->tensor, label + " value", nullptr);
    } else if (In(op, kUnary)) {
      need(1, op == "Clip" ? 3 : op == "Dropout" ? 3 : 1);
      if (op == "Clip")
        for (size_t i = 1; i < in.size(); ++i)
          if (in[i] && Count(in[i]->shape) != 1)
            Fail(label + " input " + std::to_string(i) + " has shape " + Join(in[i]->shape) +
                 "; expected a scalar bound");
      out.shape = in[0]->shape;
      if (op == "Softmax") Axis(int_attr("axis", -1), out.shape.size(), label, false);
    } else if (In(op, kBinary)) {
      need(2, 2);
      out.shape = Broadcast(in[0]->shape, in[1]->shape, label);
    } else if (op == "MatMul") {
      need(2, 2);
      std::vector<int64_t> a = in[0]->shape, b = in[1]->shape;
      if (a.empty() || b.empty()) Fail(label + " multiplies a scalar; expected tensors");
      const bool a1 = a.size() == 1, b1 = b.size() == 1;
      if (a1) a.insert(a.begin(), 1);
      if (b1) b.push_back(1);
      if (a.back() != b[b.size() - 2])
        Fail(label + " multiplies " + Join(in[0]->shape) + " by " + Join(in[1]->shape) +
             "; expected matching inner dims");
      out.shape = Broadcast(std::vector<int64_t>(a.begin(), a.end() - 2),
                            std::vector<int64_t>(b.begin(), b.end() - 2), label);
      if (!a1) out.shape.push_back(a[a.size() - 2]);
      if (!b1) out.shape.push_back(b.back());
    } else if (op == "Gemm") {
      need(2, 3);
      const auto& a = in[0]->shape;
      const auto& b = in[1]->shape;
      if (a.size() != 2 || b.size() != 2)
        Fail(label + " has inputs " + Join(a) + " and " + Join(b) + "; expected 2-d A and B");
      const bool ta = int_attr("transA", 0) != 0, tb = int_attr("transB", 0) != 0;
      const int64_t m = ta ? a[1] : a[0], k = ta ? a[0] : a[1];
      const int64_t kb = tb ? b[1] : b[0], n = tb ? b[0] : b[1];
      if (k != kb)
        Fail(label + " multiplies " + Join(a) + (ta ? "^T" : "") + " by " + Join(b) +
             (tb ? "^T" : "") + "; expected matching inner dims");
      out.shape = {m, n};
      if (in.size() == 3 && in[2] && Broadcast(out.shape, in[2]->shape, label) != out.shape)
        Fail(label + " adds C of shape " + Join(in[2]->shape) + " to " + Join(out.shape) +
             "; expected C broadcastable to A B");
    } else if (op == "Flatten") {
      need(1, 1);
      const auto& s = in[0]->shape;
      const int64_t axis = Axis(int_attr("axis", 1), s.size(), label, true);
      int64_t lo = 1, hi = 1;
      for (size_t i = 0; i < s.size(); ++i) (static_cast<int64_t>(i) < axis ? lo : hi) *= s[i];
      out.shape = {lo, hi};
    } else if (op == "Reshape") {
      need(2, 2);
      if (!in[1] || !in[1]->constant || in[1]->dtype != kInt64 || in[1]->shape.size() != 1 ||
          in[1]->ints.size() != static_cast<size_t>(in[1]->shape[0]))
        Fail(label + " takes its shape from '" + Quote(ins[1]) +
             "'; expected a constant int64 tensor of at most " + std::to_string(kMaxShapeValues) +
             " values");
      out.shape = Reshape(in[0]->shape, in[1]->ints, int_attr("allowzero", 0) != 0, label);
    } else if (op == "Concat") {
      if (in.empty()) need(1, kMaxNodeInputs);
      const Attribute* a = attr("axis");
      if (!a || !a->i) Fail(label + " has no `axis`; expected an integer axis");
      out.shape = in[0] ? in[0]->shape : std::vector<int64_t>{};
      const int64_t axis = Axis(*a->i, out.shape.size(), label, false);
      for (size_t i = 1; i < in.size(); ++i) {
        if (!in[i]) Fail(label + " has an empty input name; expected tensors to concatenate");
        const auto& s = in[i]->shape;
        bool ok = s.size() == out.shape.size();
        for (size_t d = 0; ok && d < s.size(); ++d)
          ok = static_cast<int64_t>(d) == axis || s[d] == out.shape[d];
        if (!ok)
          Fail(label + " concatenates " + Join(out.shape) + " and " + Join(s) + " on axis " +
               std::to_string(axis) + "; expected equal other dims");
        out.shape[axis] += s[axis];
        if (out.shape[axis] > kOnnxMaxActivationElements)
          Fail(what + " exceeds " + std::to_string(kOnnxMaxActivationElements) +
               " elements (kOnnxMaxActivationElements)");
      }
    }
    if (op != "Constant") {
      const int64_t n =
          Elements(out.shape, kOnnxMaxActivationElements, what, "kOnnxMaxActivationElements");
      summary_.activation_elements += n;
      summary_.max_activation_elements = std::max(summary_.max_activation_elements, n);
      if (summary_.activation_elements > kOnnxMaxTotalActivationElements)
        Fail(what + " brings the graph's intermediate tensors to more than " +
             std::to_string(kOnnxMaxTotalActivationElements) +
             " elements (kOnnxMaxTotalActivationElements)");
    }
    if (!values_.emplace(outs[0], std::move(out)).second)
      Fail(label + " writes '" + Quote(outs[0]) +
           "', which is already defined; expected each value defined once");
  }

  void CheckOperator(size_t index, const std::string& name, const std::string& op,
                     const std::string& domain) const {
    const std::string label =
        "node " + std::to_string(index) + " '" + Quote(name) + "' (" + Quote(op) + ")";
    if (domain != "" && domain != "ai.onnx")
      Fail(label + " is of domain '" + Quote(domain) + "'; expected the default ONNX domain");
    if (!In(op, kUnary) && !In(op, kBinary) && !In(op, kOther))
      Fail(label + ": operator '" + Quote(op) + "' is not supported; expected one of " +
           OnnxSupportedOperators());
  }

  Attribute Attr(std::string_view msg, size_t node) {
    Attribute a;
    ForEach(msg, "AttributeProto", [&](const Field& f) {
      switch (f.number) {
        case 1:
          a.name = Str(f, "AttributeProto.name");
          break;
        case 2:
          if (f.wire != 5) FailAt(f, "AttributeProto.f is not a 32-bit float");
          {
            const uint32_t bits = static_cast<uint32_t>(f.value);
            float v;
            std::memcpy(&v, &bits, 4);
            a.f = v;
          }
          break;
        case 3:
          a.i = static_cast<int64_t>(Varint(f, "AttributeProto.i"));
          break;
        case 5:
          if (!a.tensor.empty()) FailAt(f, "an attribute with two tensors");
          a.tensor = Bytes(f, "AttributeProto.t");
          if (a.tensor.empty()) FailAt(f, "an empty attribute tensor");
          break;
        case 6:
        case 11:
          Fail("node " + std::to_string(node) + " attribute '" + Quote(a.name) +
               "' holds a graph (control flow: If, Loop, Scan); expected a feed-forward network");
        case 10:
        case 14:
        case 15:
        case 21:
        case 22:
        case 23:
          Fail("node " + std::to_string(node) + " attribute '" + Quote(a.name) +
               "' is a tensor list, type, sparse tensor or function reference; expected numbers");
        default:
          break;
      }
    });
    return a;
  }

  static int64_t Count(const std::vector<int64_t>& s) {
    int64_t n = 1;
    for (int64_t d : s) n *= d;  // every shape here is bounded by the caps
    return n;
  }

  int64_t Axis(int64_t axis, size_t rank, const std::string& label, bool inclusive) const {
    const int64_t r = static_cast<int64_t>(rank);
    const int64_t hi = inclusive ? r : r - 1;
    if (axis < -r || axis > hi)
      Fail(label + " has axis " + std::to_string(axis) + " for a tensor of rank " +
           std::to_string(r) + "; expected " + std::to_string(-r) + " .. " + std::to_string(hi));
    return axis < 0 ? axis + r : axis;
  }

  std::vector<int64_t> Broadcast(const std::vector<int64_t>& a, const std::vector<int64_t>& b,
                                 const std::string& label) const {
    std::vector<int64_t> out(std::max(a.size(), b.size()), 1);
    for (size_t i = 0; i < out.size(); ++i) {
      const int64_t da = i < a.size() ? a[a.size() - 1 - i] : 1;
      const int64_t db = i < b.size() ? b[b.size() - 1 - i] : 1;
      if (da != db && da != 1 && db != 1)
        Fail(label + " broadcasts " + Join(a) + " with " + Join(b) +
             "; expected numpy-compatible shapes");
      out[out.size() - 1 - i] = std::max(da, db);
    }
    if (out.size() > kMaxRank)
      Fail(label + " makes a tensor of rank " + std::to_string(out.size()) + "; expected <= 8");
    Elements(out, kOnnxMaxActivationElements, label + " result", "kOnnxMaxActivationElements");
    return out;
  }

  std::vector<int64_t> Reshape(const std::vector<int64_t>& in, const std::vector<int64_t>& shape,
                               bool allowzero, const std::string& label) const {
    std::vector<int64_t> out = shape;
    int infer = -1;
    int64_t known = 1;
    for (size_t i = 0; i < out.size(); ++i) {
      if (out[i] == 0 && !allowzero) {
        if (i >= in.size())
          Fail(label + " copies dim " + std::to_string(i) + " of " + Join(in) +
               "; expected an existing dim");
        out[i] = in[i];
      }
      if (out[i] == -1) {
        if (infer >= 0) Fail(label + " has two -1 dims in " + Join(shape) + "; expected one");
        infer = static_cast<int>(i);
        continue;
      }
      if (out[i] < 1 || out[i] > kOnnxMaxActivationElements)
        Fail(label + " reshapes to " + Join(shape) + "; expected dims of 1 .. " +
             std::to_string(kOnnxMaxActivationElements) + ", 0 or one -1");
      known *= out[i];
      if (known > kOnnxMaxActivationElements)
        Fail(label + " reshapes to " + Join(shape) + ": more than " +
             std::to_string(kOnnxMaxActivationElements) + " elements");
    }
    const int64_t total = Count(in);
    if (infer >= 0) {
      if (total % known != 0)
        Fail(label + " reshapes " + Join(in) + " to " + Join(shape) + "; expected the same size");
      out[infer] = total / known;
      known = total;
    }
    if (known != total)
      Fail(label + " reshapes " + Join(in) + " (" + std::to_string(total) + " values) to " +
           Join(shape) + "; expected the same number of values");
    return out;
  }

  std::string_view file_;
  std::string path_;
  int64_t in_, out_;
  OnnxModelSummary summary_;
  int64_t weight_bytes_ = 0;
  std::unordered_map<std::string, Value> values_;
};

}  // namespace

std::string OnnxSupportedOperators() {
  std::set<std::string> all;
  for (const char* s : kUnary) all.insert(s);
  for (const char* s : kBinary) all.insert(s);
  for (const char* s : kOther) all.insert(s);
  std::string out;
  for (const std::string& s : all) out += (out.empty() ? "" : ", ") + s;
  return out;
}

OnnxModelSummary CheckOnnxModel(std::string_view bytes, const std::string& path, int input_size,
                                int output_size) {
  if (input_size < 1 || output_size < 1)
    throw ConfigError(path, 0, "",
                      "a policy of " + std::to_string(input_size) + " observations and " +
                          std::to_string(output_size) + " actions; expected at least one of each");
  return Checker(bytes, path, input_size, output_size).Run();
}

}  // namespace penumbra
