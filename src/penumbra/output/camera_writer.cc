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
  if (outputs_.rgb) CreateOutputFolder(output_dir, rel / "rgb");
  if (outputs_.depth) CreateOutputFolder(output_dir, rel / "depth");
  if (outputs_.segmentation) CreateOutputFolder(output_dir, rel / "segmentation");
  if (outputs_.range) CreateOutputFolder(output_dir, rel / "range");
  if (outputs_.normals) CreateOutputFolder(output_dir, rel / "normals");
  if (outputs_.instance_segmentation) CreateOutputFolder(output_dir, rel / "instance_segmentation");
  if (outputs_.semantic_segmentation) CreateOutputFolder(output_dir, rel / "semantic_segmentation");

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
  if (outputs_.rgb) files["rgb"] = "rgb/NNNNNN.png: 8-bit sRGB";
  if (outputs_.depth) {
    files["depth"] =
        "depth/NNNNNN.png: 16-bit z-depth in millimetres, 0 = no return, 65535 = 65.535 m or more";
  }
  if (outputs_.segmentation) {
    files["segmentation"] = "segmentation/NNNNNN.png: 16-bit MuJoCo geom id + 1, 0 = background";
  }
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
  // one PNG per image kind, at <folder>/<kind>/<name>, recorded in `written`
  auto add_times = [&](const PngWriteTimes& t) {
    encode_ns_ += static_cast<int64_t>(t.encode_sec * 1e9);
    write_ns_ += static_cast<int64_t>(t.write_sec * 1e9);
  };
  auto write8 = [&](const char* kind, const ImageU8& img) {
    PngWriteTimes t;
    const std::vector<uint8_t> bytes =
        WritePngRgb8((folder_ / kind / name).string(), img, png_options_, &t);
    add_times(t);
    written->push_back(folder_ / kind / name);
    if (on_image_) on_image_(frame, kind, bytes);
  };
  auto write16 = [&](const char* kind, const ImageU16& img) {
    PngWriteTimes t;
    const std::vector<uint8_t> bytes =
        WritePngGray16((folder_ / kind / name).string(), img, png_options_, &t);
    add_times(t);
    written->push_back(folder_ / kind / name);
    if (on_image_) on_image_(frame, kind, bytes);
  };
  if (outputs_.rgb) {
    CheckFrameImage(frame.rgb, 3, intrinsics_, camera_, frame.index, "rgb");
    write8("rgb", frame.rgb);
  }
  if (outputs_.depth) {
    CheckFrameImage(frame.depth_m, 1, intrinsics_, camera_, frame.index, "depth");
    write16("depth", DepthToMillimetres(frame.depth_m));
  }
  if (outputs_.segmentation) {
    CheckFrameImage(frame.geom_id, 1, intrinsics_, camera_, frame.index, "segmentation");
    ImageU16 seg;
    try {
      seg = SegmentationToU16(frame.geom_id);
    } catch (const Error& e) {
      throw Error(fmt::format("camera '{}' frame {}: {}", camera_, frame.index, e.what()));
    }
    write16("segmentation", seg);
  }
  // ground truth beyond the geom ids (the same pixel-centre rays)
  if (outputs_.range) {
    CheckFrameImage(frame.range_m, 1, intrinsics_, camera_, frame.index, "range");
    write16("range", DepthToMillimetres(frame.range_m));
  }
  if (outputs_.normals) {
    CheckFrameImage(frame.normal_O, 3, intrinsics_, camera_, frame.index, "normals");
    write8("normals", NormalsToRgb8(frame.normal_O));
  }
  if (outputs_.instance_segmentation) {
    CheckFrameImage(frame.body_id, 1, intrinsics_, camera_, frame.index, "instance_segmentation");
    write16("instance_segmentation", IdsToU16(frame.body_id, 1, "body"));
  }
  if (outputs_.semantic_segmentation) {
    CheckFrameImage(frame.semantic_class, 1, intrinsics_, camera_, frame.index,
                    "semantic_segmentation");
    write16("semantic_segmentation", IdsToU16(frame.semantic_class, 0, "semantic class"));
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
