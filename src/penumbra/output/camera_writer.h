#pragma once
// files of one camera under an output folder (images and JSON are written whole under a
// temporary name and renamed into place, core/output_file.h):
//
//   DIR/<camera>/rgb/NNNNNN.png           8-bit sRGB colour
//   DIR/<camera>/depth/NNNNNN.png         16-bit z-depth in millimetres (see DepthToMillimetres)
//   DIR/<camera>/segmentation/NNNNNN.png  16-bit MuJoCo geom id + 1, 0 = background
//   DIR/<camera>/range/NNNNNN.png         16-bit range along the pixel ray in millimetres
//                                         (as depth), 0 = no hit
//   DIR/<camera>/normals/NNNNNN.png       8-bit rgb round((n_O + 1) / 2 * 255) of the unit normal
//                                         facing the camera in the optical frame
//   DIR/<camera>/instance_segmentation/NNNNNN.png  16-bit body index + 1, 0 = background
//   DIR/<camera>/semantic_segmentation/NNNNNN.png  16-bit semantic class id, 0 = none
//   DIR/<camera>/frames.csv               frame,time_sec,x,y,z,qw,qx,qy,qz per frame
//   DIR/<camera>/intrinsics.json          pinhole intrinsics (OpenCV convention)
//
// NNNNNN is the per-camera frame index, zero-padded to 6 digits (more digits past
// 999999). a camera name with '/' maps to nested folders ("rover/head" ->
// DIR/rover/head/).

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "penumbra/core/image.h"
#include "penumbra/core/output_file.h"
#include "penumbra/output/camera_frame.h"
#include "penumbra/output/png_io.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// z-depth (H x W x 1, metres) -> (H x W x 1) uint16 millimetres, rounded to nearest
/// (halves away from zero). 0 = no return (depth <= 0 or not finite); a hit closer than
/// 0.5 mm is stored as 1 so that it never reads as "no return"; depths of 65.535 m or
/// more saturate to 65535.
ImageU16 DepthToMillimetres(const ImageF& depth_m);

/// MuJoCo geom ids (H x W x 1, -1 = background) -> (H x W x 1) uint16 id + 1, 0 = background.
/// @throws Error for an id < -1 or >= 65535 (does not fit a 16-bit PNG).
ImageU16 SegmentationToU16(const ImageI32& geom_id);

/// folder of a camera relative to the output folder: the name split at '/' into nested folders.
/// @throws ConfigError (key "cameras") for an empty name, an absolute path, an empty, "." or
///         ".." component, a backslash or a control character.
std::filesystem::path CameraFolder(const std::string& camera);

/// image file name of a frame: index zero-padded to 6 digits + ".png".
std::string FrameFileName(int64_t index);

/// one frames.csv row (with '\n'): frame index, time_sec, then the pose X_WO of the optical
/// frame in the world: position x y z (m) and unit quaternion qw qx qy qz with qw >= 0
/// (for qw == 0 the first non-zero of qx, qy, qz is positive). numbers are printed in the
/// shortest form that reads back to the same double (fmt "{}").
std::string FramesCsvRow(const CameraFrame& frame);

/// (H x W x 3) unit normals in [-1, 1] -> (H x W x 3) uint8 round((n + 1) / 2 * 255), clamped.
ImageU8 NormalsToRgb8(const ImageF& normal_O);

/// integer ids (H x W x 1) -> (H x W x 1) uint16 id + offset.
/// @throws Error "<what> id <id> does not fit a 16-bit PNG" when id + offset is outside 0..65535.
ImageU16 IdsToU16(const ImageI32& ids, int offset, const std::string& what);

/// the frames.csv header line (with '\n').
inline constexpr const char* kFramesCsvHeader = "frame,time_sec,x,y,z,qw,qx,qy,qz\n";

/// writes the files of one camera. WriteImages may run on several threads at once for
/// different frames; AppendPose must be called from one thread at a time, in frame order.
class CameraWriter {
 public:
  /// creates DIR/<camera>/ and the folders of the requested outputs, writes
  /// intrinsics.json and the frames.csv header (replacing existing ones).
  /// @throws ConfigError for a bad camera name (see CameraFolder);
  ///         Error naming the path if a folder or file cannot be created.
  CameraWriter(const std::string& output_dir, const std::string& camera,
               const CameraIntrinsics& intrinsics, const CameraOutputs& outputs,
               const PngEncodeOptions& png_options = {});

  CameraWriter(const CameraWriter&) = delete;
  CameraWriter& operator=(const CameraWriter&) = delete;

  /// encodes and writes the PNGs of the requested outputs (images of outputs that were
  /// not requested are ignored). all or nothing: when one fails, the frame's images written
  /// before it are removed.
  /// @throws Error if frame.camera differs, the index is negative, a requested image is
  ///         missing or its size/channels differ from the intrinsics, a geom id does not fit,
  ///         or a file cannot be written (message names the path).
  void WriteImages(const CameraFrame& frame) const;

  /// appends the frame's frames.csv row and writes it to the file (whole rows only; a row
  /// that fails to write is cut off again, core/output_file.h).
  /// @throws Error if the index is not greater than the previous one or the write fails.
  void AppendPose(const CameraFrame& frame);

  /// WriteImages then AppendPose.
  void Write(const CameraFrame& frame);

  /// `on_image` receives every image file WriteImages writes, after it is written (e.g. a run
  /// log's sensor records); empty = none.
  void set_on_image(CameraImageCallback on_image) { on_image_ = std::move(on_image); }

  const std::string& camera() const { return camera_; }
  /// DIR/<camera>
  const std::filesystem::path& folder() const { return folder_; }
  /// rows appended to frames.csv so far.
  int64_t frames_written() const { return frames_written_; }
  /// the PNG encoding and file writing of every image written so far, s (summed over the
  /// threads that ran WriteImages).
  PngWriteTimes png_times() const {
    return {1e-9 * static_cast<double>(encode_ns_.load()),
            1e-9 * static_cast<double>(write_ns_.load())};
  }

 private:
  void WriteFrameImages(const CameraFrame& frame, const std::string& name,
                        std::vector<std::filesystem::path>* written) const;

  std::string camera_;
  std::filesystem::path folder_;
  CameraIntrinsics intrinsics_;
  CameraOutputs outputs_;
  PngEncodeOptions png_options_;
  LineFile csv_;
  int64_t last_index_ = -1;
  int64_t frames_written_ = 0;
  CameraImageCallback on_image_;
  mutable std::atomic<int64_t> encode_ns_{0}, write_ns_{0};
};

}  // namespace penumbra
