#include "tests/common/schema_message.h"

#include <cctype>
#include <cstring>
#include <map>
#include <set>
#include <utility>

#include "common/lcm_schema.h"

namespace rl {
namespace {

class SchemaWriter {
 public:
  SchemaWriter(int64_t n, int salt) : n_(n), salt_(salt) {}

  void Int(int64_t v, int bytes) {
    for (int i = bytes - 1; i >= 0; --i) out_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void Struct(const std::string& name) {
    const LcmStruct& s = LcmSchemas().at(name);
    std::set<std::string> lengths;  // the fields that size an array
    for (const LcmField& f : s.fields) lengths.insert(f.dims.begin(), f.dims.end());
    std::map<std::string, int64_t> value;
    for (const LcmField& f : s.fields) {
      if (f.dims.empty() && lengths.count(f.name)) {
        value[f.name] = n_;
        Int(n_, Size(f.type));
        continue;
      }
      int64_t count = 1;
      for (const std::string& d : f.dims) {
        count *= std::isdigit(static_cast<unsigned char>(d[0])) ? std::stoll(d) : value.at(d);
      }
      for (int64_t i = 0; i < count; ++i) Element(f);
    }
  }
  std::vector<uint8_t> Take() { return std::move(out_); }

 private:
  static int Size(const std::string& type) {
    static const std::map<std::string, int> sizes = {{"int8_t", 1},  {"byte", 1},    {"boolean", 1},
                                                     {"int16_t", 2}, {"int32_t", 4}, {"float", 4},
                                                     {"int64_t", 8}, {"double", 8}};
    const auto it = sizes.find(type);
    return it == sizes.end() ? 0 : it->second;
  }

  // One element: a small value for integers and bytes (a boolean must be 0 or 1), a finite
  // float or double, a short string, or a nested struct.
  void Element(const LcmField& field) {
    const int k = ++counter_ + salt_;
    if (field.type == "string") {
      const std::string s = "s" + std::to_string(k);
      Int(static_cast<int64_t>(s.size() + 1), 4);
      out_.insert(out_.end(), s.begin(), s.end());
      out_.push_back(0);
    } else if (field.type == "float") {
      const float f = 0.5f * static_cast<float>(k);
      uint32_t bits = 0;
      std::memcpy(&bits, &f, sizeof(bits));
      Int(bits, 4);
    } else if (field.type == "double") {
      const double d = 0.25 * k;
      uint64_t bits = 0;
      std::memcpy(&bits, &d, sizeof(bits));
      Int(static_cast<int64_t>(bits), 8);
    } else if (field.type == "boolean") {
      Int(k % 2, 1);
    } else if (const int size = Size(field.type); size > 0) {
      Int(k % 100, size);
    } else {
      // A struct, maybe with its package ("rlmsg.header_t").
      const size_t dot = field.type.rfind('.');
      Struct(dot == std::string::npos ? field.type : field.type.substr(dot + 1));
    }
  }

  int64_t n_;
  int salt_;
  int counter_ = 0;
  std::vector<uint8_t> out_;
};

}  // namespace

std::vector<uint8_t> SchemaMessage(const std::string& type, int64_t fingerprint, int64_t n,
                                   int salt) {
  SchemaWriter w(n, salt);
  w.Int(fingerprint, 8);
  w.Struct(type);
  return w.Take();
}

}  // namespace rl
