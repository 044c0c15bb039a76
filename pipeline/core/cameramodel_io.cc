#include "pipeline/core/cameramodel_io.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string_view>
#include <vector>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/poses.h"

extern "C" {
#include <mrcal/mrcal.h>
}

namespace fresco {
namespace {

// ---------------------------------------------------------------------------------------
// A small reader of the Python-literal dict a .cameramodel holds. libmrcal does the real
// parse; it only prints to stderr and returns NULL on bad input, so this one runs first to
// name the line, key and element that is wrong.

struct Value {
  enum Kind { kString, kScalar, kList, kDict } kind = kScalar;
  std::string text;          // kString: contents; kScalar: token
  std::vector<Value> items;  // kList
  // kDict, in file order, each with its `key` (not a vector of pairs: a pair of an
  // incomplete type is ill-formed, and clang's libstdc++ checks refuse it).
  std::vector<Value> fields;
  std::string key;  // a kDict field's name
  int line = 0;
};

class DictParser {
 public:
  DictParser(std::string_view text, std::string name) : text_(text), name_(std::move(name)) {}

  Status ParseTopLevel(Value* dict) {
    SkipSpace();
    if (!Peek('{')) return Error("expected '{' at the start of the model");
    FRESCO_RETURN_IF_ERROR(ParseValue(dict, 0));
    SkipSpace();
    if (pos_ != text_.size()) return Error("unexpected text after the closing '}'");
    return Status::Ok();
  }

 private:
  static bool IsDelimiter(char c) {
    return c == '{' || c == '}' || c == '[' || c == ']' || c == '(' || c == ')' || c == ',' ||
           c == ':' || c == '#' || c == '\'' || c == '"' ||
           std::isspace(static_cast<unsigned char>(c));
  }

  Status Error(const std::string& what) const {
    return Status::Error(name_ + ":" + std::to_string(line_) + ": " + what);
  }

  void SkipSpace() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
        ++pos_;
      } else if (std::isspace(static_cast<unsigned char>(c))) {
        ++pos_;
      } else if (c == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else {
        break;
      }
    }
  }

  bool Peek(char c) const { return pos_ < text_.size() && text_[pos_] == c; }
  bool AtEnd() const { return pos_ >= text_.size(); }

  Status ParseString(Value* value) {
    const char quote = text_[pos_++];
    value->kind = Value::kString;
    value->text.clear();
    while (pos_ < text_.size() && text_[pos_] != quote) {
      if (text_[pos_] == '\n') return Error("unterminated string");
      if (text_[pos_] == '\\' && pos_ + 1 < text_.size()) ++pos_;
      value->text += text_[pos_++];
    }
    if (pos_ >= text_.size()) return Error("unterminated string");
    ++pos_;
    return Status::Ok();
  }

  Status ParseValue(Value* value, int depth) {
    if (depth > 32) return Error("nested too deeply");
    SkipSpace();
    value->line = line_;
    if (pos_ >= text_.size()) return Error("unexpected end of the file");
    const char c = text_[pos_];
    if (c == '\'' || c == '"') return ParseString(value);
    if (c == '{') {
      ++pos_;
      value->kind = Value::kDict;
      for (;;) {
        SkipSpace();
        if (AtEnd()) return Error("unexpected end of the file: unclosed '{'");
        if (Peek('}')) break;
        if (!(Peek('\'') || Peek('"'))) return Error("expected a quoted key or '}'");
        Value key;
        FRESCO_RETURN_IF_ERROR(ParseString(&key));
        SkipSpace();
        if (!Peek(':')) return Error("expected ':' after key '" + key.text + "'");
        ++pos_;
        Value item;
        FRESCO_RETURN_IF_ERROR(ParseValue(&item, depth + 1));
        item.key = key.text;
        value->fields.push_back(std::move(item));
        SkipSpace();
        if (Peek(',')) {
          ++pos_;
          continue;
        }
        if (AtEnd()) return Error("unexpected end of the file: unclosed '{'");
        if (!Peek('}')) return Error("expected ',' or '}' after the value of '" + key.text + "'");
      }
      ++pos_;
      return Status::Ok();
    }
    if (c == '[' || c == '(') {
      const char close = c == '[' ? ']' : ')';
      ++pos_;
      value->kind = Value::kList;
      for (;;) {
        SkipSpace();
        if (Peek(close)) break;
        Value item;
        FRESCO_RETURN_IF_ERROR(ParseValue(&item, depth + 1));
        value->items.push_back(std::move(item));
        SkipSpace();
        if (Peek(',')) {
          ++pos_;
          continue;
        }
        if (AtEnd()) return Error(std::string("unexpected end of the file: unclosed '") + c + "'");
        if (!Peek(close)) return Error(std::string("expected ',' or '") + close + "' in a list");
      }
      ++pos_;
      return Status::Ok();
    }
    // A bare token: number, True/False/None, or a bytes/raw prefix (b'...').
    const size_t start = pos_;
    while (pos_ < text_.size() && !IsDelimiter(text_[pos_])) ++pos_;
    if (pos_ == start) return Error(std::string("unexpected '") + c + "'");
    value->kind = Value::kScalar;
    value->text = std::string(text_.substr(start, pos_ - start));
    if ((Peek('\'') || Peek('"')) && value->text.size() <= 2) return ParseString(value);
    return Status::Ok();
  }

  std::string_view text_;
  std::string name_;
  size_t pos_ = 0;
  int line_ = 1;
};

const Value* FindField(const Value& dict, const std::string& key) {
  for (const Value& field : dict.fields)
    if (field.key == key) return &field;
  return nullptr;
}

// Checks that `key` is a list of `count` finite numbers; `names` names the elements.
Status CheckNumberList(const Value& dict, const std::string& key, size_t count,
                       const std::vector<std::string>& names, const std::string& file,
                       const std::string& count_hint) {
  const Value* list = FindField(dict, key);
  if (!list) return Status::Error(file + ": " + key + ": missing");
  if (list->kind != Value::kList)
    return Status::Error(file + ":" + std::to_string(list->line) + ": " + key +
                         ": expected a list of numbers");
  if (list->items.size() != count)
    return Status::Error(file + ":" + std::to_string(list->line) + ": " + key + ": " + count_hint +
                         " takes " + std::to_string(count) + " values (got " +
                         std::to_string(list->items.size()) + ")");
  for (size_t i = 0; i < count; ++i) {
    const Value& item = list->items[i];
    const std::string where = file + ":" + std::to_string(item.line) + ": " + key + ": " +
                              (i < names.size() ? names[i] : "element " + std::to_string(i));
    std::string_view token = item.text;
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    double number = 0;
    const auto result = std::from_chars(token.data(), token.data() + token.size(), number);
    if (item.kind != Value::kScalar || token.empty() || result.ec != std::errc() ||
        result.ptr != token.data() + token.size())
      return Status::Error(where + " is not a number ('" + item.text + "')");
    if (!std::isfinite(number))
      return Status::Error(where + " must be finite (got " + item.text + ")");
  }
  return Status::Ok();
}

bool IsMrcalModel(LensModel model) {
  return model == LensModel::kPinhole || model == LensModel::kOpenCV4 ||
         model == LensModel::kOpenCV5 || model == LensModel::kOpenCV8;
}

const char kSupportedNames[] =
    "LENSMODEL_PINHOLE, LENSMODEL_OPENCV4, LENSMODEL_OPENCV5, LENSMODEL_OPENCV8";

// Everything libmrcal would reject, and the lens models we do not support, with messages
// that name the line and key.
Status Diagnose(const std::string& text, const std::string& name, LensModel* model) {
  Value dict;
  FRESCO_RETURN_IF_ERROR(DictParser(text, name).ParseTopLevel(&dict));
  const Value* lensmodel = FindField(dict, "lensmodel");
  if (!lensmodel) return Status::Error(name + ": lensmodel: missing");
  const std::string at_lensmodel = name + ":" + std::to_string(lensmodel->line) + ": lensmodel: ";
  if (lensmodel->kind != Value::kString)
    return Status::Error(at_lensmodel + "expected a quoted name like 'LENSMODEL_OPENCV8'");
  if (LensModelFromName(lensmodel->text, model) && !IsMrcalModel(*model)) {
    return Status::Error(at_lensmodel + lensmodel->text +
                         " is a COLMAP model name; a .cameramodel uses mrcal's names (" +
                         kSupportedNames + ")");
  }
  if (!LensModelFromName(lensmodel->text, model)) {
    const bool known_to_mrcal = mrcal_lensmodel_type_from_name(lensmodel->text.c_str()) >= 0 ||
                                mrcal_lensmodel_type_from_name(lensmodel->text.c_str()) ==
                                    MRCAL_LENSMODEL_INVALID_BADCONFIG;
    if (known_to_mrcal)
      return Status::Error(at_lensmodel + lensmodel->text + " is not supported yet (Fresco reads " +
                           kSupportedNames + ")");
    return Status::Error(at_lensmodel + "unknown lens model '" + lensmodel->text +
                         "' (Fresco reads " + kSupportedNames + ")");
  }
  FRESCO_RETURN_IF_ERROR(CheckNumberList(dict, "intrinsics", LensModelNumParams(*model),
                                         LensModelParamNames(*model), name, lensmodel->text));
  FRESCO_RETURN_IF_ERROR(CheckNumberList(dict, "extrinsics", 6,
                                         {"rx", "ry", "rz", "tx", "ty", "tz"}, name, "rt_cam_ref"));
  FRESCO_RETURN_IF_ERROR(
      CheckNumberList(dict, "imagersize", 2, {"width", "height"}, name, "imagersize"));
  const Value* size = FindField(dict, "imagersize");
  for (size_t i = 0; i < 2; ++i) {
    const std::string& token = size->items[i].text;
    int value = 0;
    const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
    if (result.ec != std::errc() || result.ptr != token.data() + token.size() || value <= 0)
      return Status::Error(name + ":" + std::to_string(size->items[i].line) +
                           ": imagersize: " + (i == 0 ? "width" : "height") +
                           " must be a positive integer (got " + token + ")");
  }
  return Status::Ok();
}

struct MrcalModelDeleter {
  void operator()(mrcal_cameramodel_t* model) const { mrcal_free_cameramodel(&model); }
};
using MrcalModelPtr = std::unique_ptr<mrcal_cameramodel_t, MrcalModelDeleter>;

// The mrcal lens model that holds `model` without loss.
LensModel MrcalEquivalent(LensModel model) {
  switch (model) {
    case LensModel::kSimplePinhole:
    case LensModel::kColmapPinhole:
      return LensModel::kPinhole;
    case LensModel::kSimpleRadial:
    case LensModel::kRadial:
    case LensModel::kColmapOpenCV:
      return LensModel::kOpenCV4;
    case LensModel::kFullOpenCV:
      return LensModel::kOpenCV8;
    default:
      return model;
  }
}

// Shortest text that reads back to exactly `value` (locale-independent, unlike printf).
std::string ExactNumber(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::string NumberList(const std::vector<double>& values) {
  std::string out = "[";
  for (double v : values) {
    out += ' ';
    out += ExactNumber(v);
    out += ',';
  }
  out += " ]";
  return out;
}

}  // namespace

Status ParseCameraModel(const std::string& text, const std::string& name, CameraModelFile* model) {
  LensModel lens_model = LensModel::kPinhole;
  FRESCO_RETURN_IF_ERROR(Diagnose(text, name, &lens_model));
  // libmrcal's reader skips a '#' comment up to its newline without looking at the length:
  // a file ending in a comment with no newline made it read past the end. One more newline
  // changes nothing else.
  const std::string terminated = text + '\n';
  MrcalModelPtr parsed(
      mrcal_read_cameramodel_string(terminated.c_str(), static_cast<int>(terminated.size())));
  if (!parsed)
    return Status::Error(name + ": libmrcal could not parse the model (its reason is on stderr)");
  if (parsed->lensmodel.type != mrcal_lensmodel_type_from_name(LensModelName(lens_model).c_str()))
    return Status::Error(name + ": lensmodel: libmrcal read a different lens model than " +
                         LensModelName(lens_model));
  const int num_params = mrcal_lensmodel_num_params(&parsed->lensmodel);
  std::vector<double> params(parsed->intrinsics, parsed->intrinsics + num_params);
  CameraModelFile result;
  result.camera = Camera::FromParams(lens_model, static_cast<int>(parsed->imagersize[0]),
                                     static_cast<int>(parsed->imagersize[1]), params);
  FRESCO_RETURN_IF_ERROR(result.camera.Validate(name));
  result.cam_from_ref = Rigid3d::FromRt(parsed->rt_cam_ref);
  if (!result.cam_from_ref.AllFinite())
    return Status::Error(name + ": extrinsics: not a valid rt_cam_ref");
  *model = result;
  return Status::Ok();
}

Status ReadCameraModel(const std::string& path, CameraModelFile* model) {
  std::string text;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &text));
  return ParseCameraModel(text, path, model);
}

Status WriteCameraModel(const std::string& path, const CameraModelFile& model) {
  FRESCO_RETURN_IF_ERROR(
      model.camera.Validate(path + " (camera to write)").Reclassified(StatusKind::kInternal));
  if (!model.cam_from_ref.AllFinite())
    return Status::Internal(path + " (camera to write): extrinsics: not finite");
  Camera camera = model.camera;
  camera.model = MrcalEquivalent(camera.model);
  double rt[6];
  model.cam_from_ref.ToRt(rt);
  std::string text;
  text += "# Written by Fresco: an mrcal camera model. Numbers are exact (shortest round-trip).\n";
  text += "{\n";
  text += "    'lensmodel':  '" + LensModelName(camera.model) + "',\n\n";
  text += "    # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....\n";
  text += "    'intrinsics': " + NumberList(camera.Params()) + ",\n\n";
  text += "    # extrinsics are rt_fromref\n";
  text += "    'extrinsics': " + NumberList(std::vector<double>(rt, rt + 6)) + ",\n\n";
  text += "    'imagersize': [ " + std::to_string(camera.width) + ", " +
          std::to_string(camera.height) + " ],\n";
  text += "}\n";
  // What we write must be what mrcal reads: check before replacing the file.
  CameraModelFile check;
  const Status readable = ParseCameraModel(text, path, &check);
  if (!readable.ok())
    return Status::Internal(path + ": internal error: the text to write does not read back (" +
                            readable.message() + ")");
  return WriteFileAtomic(path, text);
}

Status ReadCameras(const std::string& path, std::map<int, Camera>* cameras) {
  if (std::filesystem::path(path).extension() == ".cameramodel") {
    CameraModelFile model;
    FRESCO_RETURN_IF_ERROR(ReadCameraModel(path, &model));
    cameras->clear();
    (*cameras)[1] = model.camera;
    return Status::Ok();
  }
  return ReadColmapCameras(path, cameras);
}

}  // namespace fresco
