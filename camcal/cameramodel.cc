#include "camcal/cameramodel.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "data/atomic_file.h"
#include "data/error.h"
#include "data/provenance.h"
#include "data/yaml_util.h"

namespace kincal {

namespace {

// A value of the Python literal subset mrcal writes: dict, list/tuple,
// string (also b'...'), number, True/False/None; with where it starts.
struct PyValue {
  enum class Kind { kNone, kBool, kNumber, kString, kList, kDict };
  Kind kind = Kind::kNone;
  double number = 0;
  std::string text;
  std::vector<PyValue> items;                           // kList
  std::vector<std::pair<std::string, PyValue>> fields;  // kDict, in order
  int line = 0, column = 0;
};

// Recursive-descent reader of one Python literal (ast.literal_eval's subset
// used by .cameramodel files); '#' comments run to the end of the line.
class PyLiteralReader {
 public:
  PyLiteralReader(const std::string& text, const std::string& file)
      : text_(text), file_(file) {}

  PyValue ReadDocument() {
    SkipSpace();
    if (pos_ >= text_.size()) Fail("empty file: expected a camera model dict");
    PyValue v = ReadValue();
    SkipSpace();
    if (pos_ < text_.size()) Fail("unexpected text after the model dict");
    return v;
  }

 private:
  [[noreturn]] void Fail(const std::string& message) const {
    throw InputError(file_, line_, column_, message);
  }

  char Peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }

  void Advance() {
    if (text_[pos_] == '\n') {
      ++line_;
      column_ = 1;
    } else {
      ++column_;
    }
    ++pos_;
  }

  void SkipSpace() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') Advance();
      } else if (std::isspace(static_cast<unsigned char>(c))) {
        Advance();
      } else {
        break;
      }
    }
  }

  void Expect(char c) {
    SkipSpace();
    if (Peek() != c) {
      Fail(std::string("expected '") + c + "', got " +
           (Peek() ? std::string("'") + Peek() + "'" : "end of file"));
    }
    Advance();
  }

  PyValue ReadValue() {
    SkipSpace();
    PyValue v;
    v.line = line_;
    v.column = column_;
    const char c = Peek();
    if (c == '{' || c == '[' || c == '(') {
      // A camera model nests three levels; a deep nest is not one, and
      // reading it recursively would exhaust the stack.
      if (++depth_ > kMaxDepth) {
        Fail("containers nested over " + std::to_string(kMaxDepth) +
             " levels deep: not a camera model");
      }
      if (c == '{') {
        ReadDict(&v);
      } else {
        ReadList(c == '[' ? ']' : ')', &v);
      }
      --depth_;
    } else if (c == '\'' || c == '"' ||
               ((c == 'b' || c == 'r') && pos_ + 1 < text_.size() &&
                (text_[pos_ + 1] == '\'' || text_[pos_ + 1] == '"'))) {
      v.kind = PyValue::Kind::kString;
      v.text = ReadString();
    } else if (std::isalpha(static_cast<unsigned char>(c))) {
      ReadWord(&v);
    } else {
      v.kind = PyValue::Kind::kNumber;
      v.number = ReadNumber();
    }
    return v;
  }

  void ReadDict(PyValue* v) {
    v->kind = PyValue::Kind::kDict;
    Advance();  // {
    std::set<std::string> seen;
    for (;;) {
      SkipSpace();
      if (Peek() == '}') break;
      const int key_line = line_, key_column = column_;
      const PyValue key = ReadValue();
      if (key.kind != PyValue::Kind::kString) {
        throw InputError(file_, key_line, key_column,
                         "expected a quoted key in the model dict");
      }
      if (!seen.insert(key.text).second) {
        throw InputError(file_, key_line, key_column,
                         "duplicate key '" + key.text + "'");
      }
      Expect(':');
      v->fields.emplace_back(key.text, ReadValue());
      SkipSpace();
      if (Peek() == ',') {
        Advance();
      } else if (Peek() != '}') {
        Fail("expected ',' or '}' in the model dict");
      }
    }
    Advance();  // }
  }

  void ReadList(char close, PyValue* v) {
    v->kind = PyValue::Kind::kList;
    Advance();  // [ or (
    for (;;) {
      SkipSpace();
      if (Peek() == close) break;
      v->items.push_back(ReadValue());
      SkipSpace();
      if (Peek() == ',') {
        Advance();
      } else if (Peek() != close) {
        Fail(std::string("expected ',' or '") + close + "' in a list");
      }
    }
    Advance();
  }

  std::string ReadString() {
    if (Peek() == 'b' || Peek() == 'r') Advance();  // prefix
    const char quote = Peek();
    Advance();
    std::string s;
    for (;;) {
      if (pos_ >= text_.size() || Peek() == '\n') Fail("unterminated string");
      const char c = Peek();
      Advance();
      if (c == quote) break;
      if (c == '\\' && pos_ < text_.size()) {
        s += Peek();
        Advance();
      } else {
        s += c;
      }
    }
    return s;
  }

  void ReadWord(PyValue* v) {
    std::string word;
    while (std::isalnum(static_cast<unsigned char>(Peek())) || Peek() == '_') {
      word += Peek();
      Advance();
    }
    if (word == "True" || word == "False") {
      v->kind = PyValue::Kind::kBool;
      v->number = word == "True" ? 1 : 0;
    } else if (word == "None") {
      v->kind = PyValue::Kind::kNone;
    } else {
      throw InputError(file_, v->line, v->column,
                       "unexpected word '" + word +
                           "': a camera model is a Python literal (numbers, "
                           "strings, lists, dicts)");
    }
  }

  double ReadNumber() {
    const char* begin = text_.c_str() + pos_;
    char* end = nullptr;
    const double x = std::strtod(begin, &end);
    if (end == begin) {
      Fail(Peek() ? std::string("unexpected character '") + Peek() + "'"
                  : "unexpected end of file");
    }
    for (const char* p = begin; p < end; ++p) Advance();
    return x;
  }

  const std::string& text_;
  const std::string& file_;
  static constexpr int kMaxDepth = 32;
  size_t pos_ = 0;
  int line_ = 1, column_ = 1;
  int depth_ = 0;  // open containers around the value being read
};

[[noreturn]] void FailAt(const std::string& file, const PyValue& v,
                         const std::string& message) {
  throw InputError(file, v.line, v.column, message);
}

std::vector<double> Numbers(const std::string& file, const PyValue& v,
                            const std::string& what) {
  if (v.kind != PyValue::Kind::kList)
    FailAt(file, v, what + ": expected a list");
  std::vector<double> out;
  for (const PyValue& item : v.items) {
    if (item.kind != PyValue::Kind::kNumber || !std::isfinite(item.number)) {
      FailAt(file, item, what + ": expected finite numbers");
    }
    out.push_back(item.number);
  }
  return out;
}

// Coefficient count of a supported lens model; -1 when unsupported.
int NumDistortion(const std::string& lensmodel) {
  static const std::map<std::string, int> kSupported = {
      {"LENSMODEL_PINHOLE", 0},
      {"LENSMODEL_OPENCV4", 4},
      {"LENSMODEL_OPENCV5", 5},
      {"LENSMODEL_OPENCV8", 8}};
  const auto it = kSupported.find(lensmodel);
  return it == kSupported.end() ? -1 : it->second;
}

std::string Join(const std::vector<double>& values) {
  std::string s = "[";
  for (double x : values) s += " " + FormatDouble(x) + ",";
  return s + " ]";
}

void ReadIntrinsics(const std::string& file, const PyValue& lens,
                    const PyValue& intrinsics, const PyValue& imagersize,
                    CameraModelFile* model) {
  if (lens.kind != PyValue::Kind::kString) {
    FailAt(file, lens, "lensmodel: expected a string");
  }
  std::string name = lens.text;
  const std::string legacy = "DISTORTION_";
  if (name.rfind(legacy, 0) == 0) {
    name = "LENSMODEL_" + name.substr(legacy.size());
  }
  const int num_distortion = NumDistortion(name);
  if (num_distortion < 0) {
    FailAt(file, lens,
           "lensmodel '" + name +
               "' is not supported: kincal reads LENSMODEL_PINHOLE, "
               "LENSMODEL_OPENCV4, LENSMODEL_OPENCV5 and LENSMODEL_OPENCV8 "
               "(OpenCV's radial-tangential model); re-solve the camera "
               "with one of them in mrcal");
  }
  const std::vector<double> values = Numbers(file, intrinsics, "intrinsics");
  if (static_cast<int>(values.size()) != 4 + num_distortion) {
    FailAt(file, intrinsics,
           "intrinsics: " + name + " has " +
               std::to_string(4 + num_distortion) + " numbers, got " +
               std::to_string(values.size()));
  }
  if (!(values[0] > 0 && values[1] > 0)) {
    FailAt(file, intrinsics, "intrinsics: expected fx > 0 and fy > 0");
  }
  const std::vector<double> size = Numbers(file, imagersize, "imagersize");
  if (size.size() != 2 || !(size[0] >= 1 && size[1] >= 1) ||
      size[0] != std::floor(size[0]) || size[1] != std::floor(size[1]) ||
      size[0] > 100000 || size[1] > 100000) {
    FailAt(file, imagersize,
           "imagersize: expected [width, height], two positive integers");
  }
  CameraIntrinsics& in = model->intrinsics;
  in = CameraIntrinsics::FromArray(values.data(), 0);
  in.distortion.assign(values.begin() + 4, values.end());
  in.width = static_cast<int>(size[0]);
  in.height = static_cast<int>(size[1]);
}

}  // namespace

std::string MrcalLensModelName(int num_distortion) {
  switch (num_distortion) {
    case 0:
      return "LENSMODEL_PINHOLE";
    case 4:
    case 5:
    case 8:
      return "LENSMODEL_OPENCV" + std::to_string(num_distortion);
    default:
      throw InputError("no mrcal lens model with " +
                       std::to_string(num_distortion) +
                       " OpenCV distortion coefficients (0, 4, 5 or 8)");
  }
}

CameraModelFile ParseCameraModel(const std::string& text,
                                 const std::string& file) {
  const PyValue root = PyLiteralReader(text, file).ReadDocument();
  if (root.kind != PyValue::Kind::kDict) {
    FailAt(file, root, "expected a camera model dict ({ ... })");
  }
  std::map<std::string, const PyValue*> fields;
  for (const auto& [key, value] : root.fields) fields[key] = &value;
  for (const auto& [old_key, key] :
       {std::pair<std::string, std::string>{"distortion_model", "lensmodel"},
        {"lens_model", "lensmodel"}}) {
    if (fields.count(old_key) && !fields.count(key)) {
      fields[key] = fields[old_key];
    }
  }
  for (const char* key :
       {"lensmodel", "intrinsics", "extrinsics", "imagersize"}) {
    if (!fields.count(key)) {
      FailAt(file, root, std::string("missing key '") + key + "'");
    }
  }
  CameraModelFile model;
  ReadIntrinsics(file, *fields["lensmodel"], *fields["intrinsics"],
                 *fields["imagersize"], &model);
  const std::vector<double> rt =
      Numbers(file, *fields["extrinsics"], "extrinsics");
  if (rt.size() != 6) {
    FailAt(file, *fields["extrinsics"],
           "extrinsics: expected 6 numbers (rt_cam_ref: rotation vector, "
           "translation), got " +
               std::to_string(rt.size()));
  }
  model.cam_from_ref.R =
      RotationMatrixFromVector(Eigen::Vector3d(rt[0], rt[1], rt[2]));
  model.cam_from_ref.t = Eigen::Vector3d(rt[3], rt[4], rt[5]);
  if (fields.count("valid_intrinsics_region") &&
      fields["valid_intrinsics_region"]->kind != PyValue::Kind::kNone) {
    const PyValue& region = *fields["valid_intrinsics_region"];
    if (region.kind != PyValue::Kind::kList) {
      FailAt(file, region, "valid_intrinsics_region: expected a list");
    }
    for (const PyValue& point : region.items) {
      const std::vector<double> uv =
          Numbers(file, point, "valid_intrinsics_region");
      if (uv.size() != 2) {
        FailAt(file, point, "valid_intrinsics_region: expected [u, v] pairs");
      }
      model.valid_intrinsics_region.emplace_back(uv[0], uv[1]);
    }
  }
  return model;
}

CameraModelFile ReadCameraModel(const std::string& path) {
  return ParseCameraModel(ReadFile(path), path);
}

std::string CameraModelToText(const CameraModelFile& model) {
  const CameraIntrinsics& in = model.intrinsics;
  std::vector<double> intrinsics = {in.fx, in.fy, in.cx, in.cy};
  intrinsics.insert(intrinsics.end(), in.distortion.begin(),
                    in.distortion.end());
  const Eigen::Vector3d r = RotationVectorFromMatrix(model.cam_from_ref.R);
  const Eigen::Vector3d& t = model.cam_from_ref.t;
  std::ostringstream os;
  os << "# written by " << ToolVersion() << ": " << CommandLine() << "\n";
  if (!in.name.empty()) os << "# camera '" << in.name << "'\n";
  os << "{\n"
     << "    'lensmodel':  '"
     << MrcalLensModelName(static_cast<int>(in.distortion.size())) << "',\n\n"
     << "    # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....\n"
     << "    'intrinsics': " << Join(intrinsics) << ",\n\n";
  if (!model.valid_intrinsics_region.empty()) {
    os << "    'valid_intrinsics_region': [\n";
    for (const Eigen::Vector2d& p : model.valid_intrinsics_region) {
      os << "    [ " << FormatDouble(p.x()) << ", " << FormatDouble(p.y())
         << " ],\n";
    }
    os << "],\n\n";
  }
  os << "    # extrinsics are rt_fromref\n"
     << "    'extrinsics': " << Join({r.x(), r.y(), r.z(), t.x(), t.y(), t.z()})
     << ",\n\n"
     << "    'imagersize': [ " << in.width << ", " << in.height << ", ],\n"
     << "}\n";
  return os.str();
}

void WriteCameraModel(const std::string& path, const CameraModelFile& model) {
  WriteFileAtomic(path, CameraModelToText(model));
}

Rig RigFromCameraModels(
    const std::vector<std::pair<std::string, CameraModelFile>>& models,
    double unit_mm) {
  Require(unit_mm > 0 && std::isfinite(unit_mm),
          "the model unit must be a positive length in mm (1000 for metres)");
  Require(!models.empty(), "no camera models given");
  const Rigid3 ref_from_cam0 = models[0].second.cam_from_ref.Inverse();
  Rig rig;
  std::set<std::string> names;
  for (const auto& [name, model] : models) {
    Require(!name.empty(), "a camera needs a name");
    Require(names.insert(name).second, "duplicate camera name '" + name + "'");
    Camera cam;
    cam.intrinsics = model.intrinsics;
    cam.intrinsics.name = name;
    cam.valid_intrinsics_region = model.valid_intrinsics_region;
    if (!rig.cameras.empty()) {
      cam.cam_from_rig = model.cam_from_ref * ref_from_cam0;
      cam.cam_from_rig.t *= unit_mm;
    }
    rig.cameras.push_back(cam);
  }
  return rig;
}

std::vector<CameraModelFile> CameraModelsFromRig(const Rig& rig,
                                                 double unit_mm) {
  Require(unit_mm > 0 && std::isfinite(unit_mm),
          "the model unit must be a positive length in mm (1000 for metres)");
  std::vector<CameraModelFile> models;
  for (const Camera& cam : rig.cameras) {
    CameraModelFile model;
    model.intrinsics = cam.intrinsics;
    model.cam_from_ref = cam.cam_from_rig;
    model.cam_from_ref.t /= unit_mm;
    model.valid_intrinsics_region = cam.valid_intrinsics_region;
    models.push_back(model);
  }
  return models;
}

}  // namespace kincal
