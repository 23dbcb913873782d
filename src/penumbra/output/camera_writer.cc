#include "penumbra/output/camera_writer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <system_error>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

template <typename T>
void CheckFrameImage(const Image<T>& image, int channels, const CameraIntrinsics& intr,
                     const std::string& camera, int64_t index, const char* what) {
  if (image.empty()) {
    throw Error(fmt::format("camera '{}' frame {}: {} output requested but the image is empty",
                            camera, index, what));
  }
  if (image.width != intr.width || image.height != intr.height || image.channels != channels ||
      image.data.size() != static_cast<size_t>(image.width) * image.height * image.channels) {
    throw Error(fmt::format(
        "camera '{}' frame {}: {} image is {} x {} x {} ({} samples); expected {} x {} x {}",
        camera, index, what, image.width, image.height, image.channels, image.data.size(),
        intr.width, intr.height, channels));
  }
}

// the frame's image of a kind of PixelType kF32 / kI32 (scene/image_kind.h)
const ImageF& FloatImage(const CameraFrame& f, ImageKind kind) {
  switch (kind) {
    case ImageKind::kDepth:
      return f.depth_m;
    case ImageKind::kRange:
      return f.range_m;
    case ImageKind::kNormals:
      return f.normal_O;
    default:
      throw Error("image kind '" + std::string(ImageKindName(kind)) + "' is not float");
  }
}
const ImageI32& IdImage(const CameraFrame& f, ImageKind kind) {
  switch (kind) {
    case ImageKind::kSegmentation:
      return f.geom_id;
    case ImageKind::kInstanceSegmentation:
      return f.body_id;
    case ImageKind::kSemanticSegmentation:
      return f.semantic_class;
    default:
      throw Error("image kind '" + std::string(ImageKindName(kind)) + "' has no ids");
  }
}

}  // namespace

ImageU16 DepthToMillimetres(const ImageF& depth_m) {
  ImageU16 out(depth_m.width, depth_m.height, depth_m.channels);
  for (size_t i = 0; i < depth_m.data.size(); ++i) {
    const double d = depth_m.data[i];
    uint16_t mm = 0;
    if (std::isfinite(d) && d > 0) {
      const double r = std::round(d * 1000.0);
      mm = r >= 65535.0 ? uint16_t{65535} : r < 1.0 ? uint16_t{1} : static_cast<uint16_t>(r);
    }
    out.data[i] = mm;
  }
  return out;
}

ImageU16 SegmentationToU16(const ImageI32& geom_id) {
  ImageU16 out(geom_id.width, geom_id.height, geom_id.channels);
  for (size_t i = 0; i < geom_id.data.size(); ++i) {
    const int32_t id = geom_id.data[i];
    if (id < -1 || id >= 65535) {
      throw Error(fmt::format(
          "segmentation: geom id {} at sample {} does not fit a 16-bit PNG (expected -1..65534)",
          id, i));
    }
    out.data[i] = static_cast<uint16_t>(id + 1);
  }
  return out;
}

fs::path CameraFolder(const std::string& camera) {
  auto bad = [&](const std::string& why) {
    return ConfigError("", 0, "cameras",
                       "camera name '" + camera + "' cannot name an output folder: " + why +
                           "; expected a relative name like \"front\" or \"rover/head\"");
  };
  if (camera.empty()) throw bad("it is empty");
  if (camera.front() == '/') throw bad("it is an absolute path");
  fs::path folder;
  size_t start = 0;
  while (start <= camera.size()) {
    size_t end = camera.find('/', start);
    if (end == std::string::npos) end = camera.size();
    const std::string part = camera.substr(start, end - start);
    if (part.empty()) throw bad("it has an empty path component");
    if (part == "." || part == "..") throw bad("it has a '" + part + "' component");
    for (unsigned char c : part) {
      if (c == '\\') throw bad("it contains a backslash");
      if (c < 0x20 || c == 0x7f) throw bad("it contains a control character");
    }
    folder /= part;
    start = end + 1;
  }
  return folder;
}

ImageU8 NormalsToRgb8(const ImageF& n) {
  ImageU8 rgb(n.width, n.height, 3);
  for (size_t i = 0; i < n.data.size(); ++i) {
    const float v = std::clamp((n.data[i] + 1.0f) * 0.5f * 255.0f, 0.0f, 255.0f);
    rgb.data[i] = static_cast<uint8_t>(std::lround(v));
  }
  return rgb;
}

ImageU16 IdsToU16(const ImageI32& ids, int offset, const std::string& what) {
  ImageU16 out(ids.width, ids.height, 1);
  for (size_t i = 0; i < ids.data.size(); ++i) {
    const int64_t v = static_cast<int64_t>(ids.data[i]) + offset;
    if (v < 0 || v > 65535)
      throw Error(what + " id " + std::to_string(ids.data[i]) + " does not fit a 16-bit PNG");
    out.data[i] = static_cast<uint16_t>(v);
  }
  return out;
}

std::string FrameFileName(int64_t index) { return fmt::format("{:06d}.png", index); }

std::string FramesCsvRow(const CameraFrame& frame) {
  Eigen::Quaterniond q(frame.X_WO.linear());
  q.normalize();
  // canonical sign: q and -q are the same rotation
  bool flip = q.w() < 0;
  if (q.w() == 0) {
    const double first = q.x() != 0 ? q.x() : q.y() != 0 ? q.y() : q.z();
    flip = first < 0;
  }
  if (flip) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d p = frame.X_WO.translation();
  return fmt::format("{},{},{},{},{},{},{},{},{}\n", frame.index, frame.time_sec, p.x(), p.y(),
                     p.z(), q.w(), q.x(), q.y(), q.z());
}

CameraWriter::CameraWriter(const std::string& output_dir, const std::string& camera,
                           const CameraIntrinsics& intrinsics, const CameraOutputs& outputs,
                           const PngEncodeOptions& png_options)
    : camera_(camera),
      folder_(fs::path(output_dir) / CameraFolder(camera)),
      intrinsics_(intrinsics),
      outputs_(outputs),
      png_options_(png_options) {
  png_options_.ValidateOrThrow();
  if (intrinsics.width <= 0 || intrinsics.height <= 0) {
    throw Error(fmt::format("camera '{}': image size {} x {} must be positive", camera,
                            intrinsics.width, intrinsics.height));
  }
  const fs::path rel = CameraFolder(camera);
  CreateOutputFolder(output_dir, rel);
  for (const ImageKindInfo& k : kImageKinds)
    if (outputs_[k.kind]) CreateOutputFolder(output_dir, rel / k.folder);

  // ordered_json keeps the key order below
  nlohmann::ordered_json j;
  j["camera"] = camera;
  j["width"] = intrinsics.width;
  j["height"] = intrinsics.height;
  j["fx"] = intrinsics.fx;
  j["fy"] = intrinsics.fy;
  j["cx"] = intrinsics.cx;
  j["cy"] = intrinsics.cy;
  j["model"] = "pinhole";
  j["optical_frame"] = "opencv (x right, y down, z forward)";
  nlohmann::ordered_json files = nlohmann::ordered_json::object();
  for (const ImageKindInfo& k : kImageKinds)
    if (outputs_[k.kind] && !k.file_note.empty()) files[std::string(k.name)] = k.file_note;
  files["frames"] =
      "frames.csv: pose of the optical frame in the world (m, unit quaternion, qw >= 0)";
  j["files"] = files;
  WriteFileAtomic(folder_ / "intrinsics.json", j.dump(2) + "\n");

  // every row reaches the file at once (buffer 0): rows never lag the images on disk
  csv_ = LineFile(folder_ / "frames.csv", 0);
  csv_.Append(kFramesCsvHeader);
}

void CameraWriter::WriteImages(const CameraFrame& frame) const {
  if (frame.camera != camera_) {
    throw Error("frame of camera '" + frame.camera + "' given to the writer of camera '" + camera_ +
                "'");
  }
  if (frame.index < 0) {
    throw Error(fmt::format("camera '{}': negative frame index {}", camera_, frame.index));
  }
  const std::string name = FrameFileName(frame.index);
  // a frame is written whole or not at all: if one image fails, the frame's images written
  // before it are removed again (the frame gets no frames.csv row either)
  std::vector<fs::path> written;
  try {
    WriteFrameImages(frame, name, &written);
  } catch (...) {
    for (const fs::path& p : written) {
      std::error_code ec;
      fs::remove(p, ec);
    }
    throw;
  }
}

void CameraWriter::WriteFrameImages(const CameraFrame& frame, const std::string& name,
                                    std::vector<fs::path>* written) const {
  // one PNG per image kind, at <folder>/<kind folder>/<name>, recorded in `written`, in the
  // order of the image-kind table (scene/image_kind.h)
  for (const ImageKindInfo& k : kImageKinds) {
    if (!outputs_[k.kind]) continue;
    const std::string kind(k.name);
    const fs::path path = folder_ / k.folder / name;
    std::vector<uint8_t> bytes;
    PngWriteTimes t;
    switch (k.encoding) {
      case ImageEncoding::kPngRgb8:
        CheckFrameImage(frame.rgb, k.channels, intrinsics_, camera_, frame.index, kind.c_str());
        bytes = WritePngRgb8(path.string(), frame.rgb, png_options_, &t);
        break;
      case ImageEncoding::kPngRgb8Normals: {
        const ImageF& img = FloatImage(frame, k.kind);
        CheckFrameImage(img, k.channels, intrinsics_, camera_, frame.index, kind.c_str());
        bytes = WritePngRgb8(path.string(), NormalsToRgb8(img), png_options_, &t);
        break;
      }
      case ImageEncoding::kPngGray16Millimetres: {
        const ImageF& img = FloatImage(frame, k.kind);
        CheckFrameImage(img, k.channels, intrinsics_, camera_, frame.index, kind.c_str());
        bytes = WritePngGray16(path.string(), DepthToMillimetres(img), png_options_, &t);
        break;
      }
      case ImageEncoding::kPngGray16IdPlusOne:
      case ImageEncoding::kPngGray16Id: {
        const ImageI32& ids = IdImage(frame, k.kind);
        CheckFrameImage(ids, k.channels, intrinsics_, camera_, frame.index, kind.c_str());
        ImageU16 u16;
        if (k.kind == ImageKind::kSegmentation) {
          // geom ids: the message names the camera, frame and sample
          try {
            u16 = SegmentationToU16(ids);
          } catch (const Error& e) {
            throw Error(fmt::format("camera '{}' frame {}: {}", camera_, frame.index, e.what()));
          }
        } else {
          const bool plus_one = k.encoding == ImageEncoding::kPngGray16IdPlusOne;
          u16 = IdsToU16(ids, plus_one ? 1 : 0,
                         k.kind == ImageKind::kInstanceSegmentation ? "body" : "semantic class");
        }
        bytes = WritePngGray16(path.string(), u16, png_options_, &t);
        break;
      }
    }
    encode_ns_ += static_cast<int64_t>(t.encode_sec * 1e9);
    write_ns_ += static_cast<int64_t>(t.write_sec * 1e9);
    written->push_back(path);
    if (on_image_) on_image_(frame, kind, bytes);
  }
}

void CameraWriter::AppendPose(const CameraFrame& frame) {
  if (frame.index <= last_index_) {
    throw Error(
        fmt::format("camera '{}': frame {} appended after frame {}; expected increasing "
                    "frame indices",
                    camera_, frame.index, last_index_));
  }
  csv_.Append(FramesCsvRow(frame));
  last_index_ = frame.index;
  ++frames_written_;
}

void CameraWriter::Write(const CameraFrame& frame) {
  WriteImages(frame);
  AppendPose(frame);
}

}  // namespace penumbra
