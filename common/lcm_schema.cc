#include "common/lcm_schema.h"

#include <array>
#include <cctype>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <utility>

namespace rl {
namespace {

// The .lcm files of lcmtypes/, embedded by the build: {struct name, file text}.
constexpr std::pair<const char*, const char*> kEmbedded[] = {
#include "lcm_schemas.inc"
};

// Splits .lcm text into identifiers/numbers and the punctuation { } [ ] ; , skipping comments.
std::vector<std::string> Tokenize(std::string_view text, const std::string& file) {
  std::vector<std::string> tokens;
  size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (text.substr(i, 2) == "//") {
      i = text.find('\n', i);
      if (i == std::string_view::npos) i = text.size();
    } else if (text.substr(i, 2) == "/*") {
      const size_t end = text.find("*/", i + 2);
      if (end == std::string_view::npos) throw std::invalid_argument(file + ": unclosed comment");
      i = end + 2;
    } else if (std::string_view("{}[];,=").find(c) != std::string_view::npos) {
      tokens.emplace_back(1, c);
      ++i;
    } else if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.') {
      size_t j = i;
      while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) ||
                                 text[j] == '_' || text[j] == '.')) {
        ++j;
      }
      tokens.emplace_back(text.substr(i, j - i));
      i = j;
    } else {
      throw std::invalid_argument(file + ": unexpected character '" + std::string(1, c) + "'");
    }
  }
  return tokens;
}

// Encoded size of a primitive type, 0 for a string, -1 for anything else (a struct).
int PrimitiveSize(const std::string& type) {
  static const std::map<std::string, int> sizes = {{"int8_t", 1},  {"byte", 1},    {"boolean", 1},
                                                   {"int16_t", 2}, {"int32_t", 4}, {"float", 4},
                                                   {"int64_t", 8}, {"double", 8},  {"string", 0}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? -1 : it->second;
}

bool IsInteger(const std::string& type) {
  return type == "int8_t" || type == "int16_t" || type == "int32_t" || type == "int64_t";
}

// A struct compiled for walking: per field its element kind and its dimensions.
constexpr int kMaxFields = 64;
struct Op {
  int size = 0;                           // primitive bytes; 0: string; -1: struct
  const struct Program* inner = nullptr;  // the struct's program when size == -1
  // Dimensions: a constant (field < 0) or the value of an earlier field.
  std::vector<std::pair<int64_t, int>> dims;
  bool record = false;  // an integer scalar: keep its value for later dimensions
};
struct Program {
  std::vector<Op> ops;
};

// Reads big-endian fields, remembering whether anything ran past the end or was refused.
class Walker {
 public:
  Walker(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  void Skip(int64_t n) {
    if (!ok_ || n < 0 || static_cast<uint64_t>(n) > size_ - pos_) {
      ok_ = false;
      return;
    }
    pos_ += static_cast<size_t>(n);
  }
  int64_t ReadInt(int bytes) {
    if (!ok_ || static_cast<size_t>(bytes) > size_ - pos_) {
      ok_ = false;
      return 0;
    }
    uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | data_[pos_ + static_cast<size_t>(i)];
    pos_ += static_cast<size_t>(bytes);
    const int shift = 64 - 8 * bytes;  // sign-extend
    return static_cast<int64_t>(v << shift) >> shift;
  }
  // A string: int32 length including the terminating NUL, then the bytes. lcm-gen's encoder
  // writes a string up to its first NUL, so one with a NUL inside (or none at its end) would not
  // re-encode as received: refused.
  void String() {
    const int64_t len = ReadInt(4);
    if (len < 1) ok_ = false;
    const size_t at = pos_;
    Skip(len);
    if (!ok_) return;
    const size_t n = static_cast<size_t>(len) - 1;
    if (data_[at + n] != 0 || std::memchr(data_ + at, 0, n) != nullptr) {
      ok_ = false;
      bad_string_ = true;
    }
  }
  void Struct(const Program& p) {
    std::array<int64_t, kMaxFields> values{};
    for (size_t f = 0; f < p.ops.size() && ok_; ++f) {
      const Op& op = p.ops[f];
      int64_t count = 1;
      for (const auto& [constant, field] : op.dims) {
        const int64_t n = field < 0 ? constant : values[static_cast<size_t>(field)];
        if (n < 0 || n > kMaxArrayElements) ok_ = false;
        count *= n;
        if (count > kMaxArrayElements) ok_ = false;
        if (!ok_) return;
      }
      if (op.record) {
        values[f] = ReadInt(op.size);
      } else if (op.size > 0) {
        Skip(count * op.size);
      } else {
        for (int64_t k = 0; k < count && ok_; ++k) {
          if (op.size == 0) {
            String();
          } else {
            Struct(*op.inner);
          }
        }
      }
    }
  }
  const char* Finish() const {
    if (bad_string_) return "string with a NUL inside";
    if (!ok_) return "truncated or bad length";
    if (pos_ != size_) return "trailing bytes";
    return nullptr;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  bool ok_ = true;
  bool bad_string_ = false;  // a string with a NUL inside or no terminating NUL
};

struct Compiled {
  std::map<std::string, LcmStruct> schemas;
  std::map<std::string, Program, std::less<>> programs;
  std::vector<std::string> compiling;  // the structs being compiled, to refuse a cycle
};

// Compiles `name` (and the structs it contains) into c->programs.
const Program& Compile(const std::string& name, Compiled* c) {
  if (const auto it = c->programs.find(name); it != c->programs.end()) return it->second;
  const auto schema = c->schemas.find(name);
  if (schema == c->schemas.end()) {
    throw std::invalid_argument("lcmtypes: no schema for struct '" + name + "'");
  }
  for (const std::string& open : c->compiling) {
    if (open == name)
      throw std::invalid_argument("lcmtypes: struct '" + name + "' contains itself");
  }
  c->compiling.push_back(name);
  Program program;
  const std::vector<LcmField>& fields = schema->second.fields;
  if (fields.size() > kMaxFields) {
    throw std::invalid_argument("lcmtypes: struct '" + name + "' has more than 64 fields");
  }
  for (const LcmField& field : fields) {
    Op op;
    op.size = PrimitiveSize(field.type);
    if (op.size < 0) {
      // Struct names may carry their package ("rlmsg.header_t").
      const size_t dot = field.type.rfind('.');
      op.inner = &Compile(dot == std::string::npos ? field.type : field.type.substr(dot + 1), c);
    }
    for (const std::string& dim : field.dims) {
      if (std::isdigit(static_cast<unsigned char>(dim[0]))) {
        op.dims.emplace_back(std::stoll(dim), -1);
        continue;
      }
      int index = -1;
      for (size_t f = 0; f < program.ops.size(); ++f) {
        if (fields[f].name == dim) index = static_cast<int>(f);
      }
      op.dims.emplace_back(0, index);  // ParseLcmStruct checked that it exists
    }
    op.record = field.dims.empty() && IsInteger(field.type);
    program.ops.push_back(std::move(op));
  }
  c->compiling.pop_back();
  return c->programs.emplace(name, std::move(program)).first->second;
}

const Compiled& CompiledSchemas() {
  static const Compiled compiled = [] {
    Compiled c;
    for (const auto& [name, text] : kEmbedded) {
      LcmStruct schema = ParseLcmStruct(text, std::string(name) + ".lcm");
      if (schema.name != name) {
        throw std::invalid_argument(std::string(name) + ".lcm: holds struct '" + schema.name +
                                    "'; a file must be named after its struct");
      }
      c.schemas.emplace(name, std::move(schema));
    }
    for (const auto& [name, schema] : c.schemas) Compile(name, &c);
    return c;
  }();
  return compiled;
}

}  // namespace

LcmStruct ParseLcmStruct(std::string_view text, const std::string& file_name) {
  const std::vector<std::string> tokens = Tokenize(text, file_name);
  size_t i = 0;
  const auto next = [&](const char* what) -> const std::string& {
    if (i >= tokens.size()) {
      throw std::invalid_argument(file_name + ": expected " + what + " at the end of the file");
    }
    return tokens[i++];
  };
  const auto expect = [&](const std::string& token) {
    const std::string& got = next(token.c_str());
    if (got != token) {
      throw std::invalid_argument(file_name + ": expected '" + token + "', got '" + got + "'");
    }
  };
  LcmStruct s;
  if (i < tokens.size() && tokens[i] == "package") {
    ++i;
    s.package = next("a package name");
    expect(";");
  }
  expect("struct");
  s.name = next("a struct name");
  expect("{");
  while (i < tokens.size() && tokens[i] != "}") {
    LcmField f;
    f.type = next("a type");
    if (f.type == "const") {
      throw std::invalid_argument(file_name + ": constants are not supported");
    }
    f.name = next("a field name");
    while (i < tokens.size() && tokens[i] == "[") {
      ++i;
      const std::string& dim = next("a dimension");
      if (!std::isdigit(static_cast<unsigned char>(dim[0]))) {
        bool found = false;
        for (const LcmField& earlier : s.fields) {
          found |= earlier.name == dim && earlier.dims.empty() && IsInteger(earlier.type);
        }
        if (!found) {
          throw std::invalid_argument(file_name + ": dimension '" + dim + "' of '" + f.name +
                                      "' is not an earlier integer field");
        }
      }
      f.dims.push_back(dim);
      expect("]");
    }
    expect(";");
    s.fields.push_back(std::move(f));
  }
  expect("}");
  if (i != tokens.size()) {
    throw std::invalid_argument(file_name + ": unexpected '" + tokens[i] + "' after the struct");
  }
  return s;
}

const std::map<std::string, LcmStruct>& LcmSchemas() { return CompiledSchemas().schemas; }

const char* PrescanEncoded(std::string_view type, const uint8_t* data, size_t size) {
  const Compiled& c = CompiledSchemas();
  const auto it = c.programs.find(type);
  if (it == c.programs.end()) return "no schema";
  Walker w(data, size);
  w.Skip(8);  // fingerprint
  w.Struct(it->second);
  return w.Finish();
}

}  // namespace rl
