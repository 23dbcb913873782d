#pragma once
// the run log (.plog): a versioned, chunked binary record of one `penumbra run`:
// a header (versions, the world and composed model texts, asset hashes, seed, command line,
// timestep and the state layout with names), then per physics step the state MuJoCo needs to
// continue bit for bit, plus events (commands, effect changes, notes) and optional
// sensor outputs. the byte layout is specified in docs/run-log.md; this file holds the
// in-memory types the writer (runlog/run_log_writer.h) takes and the reader
// (runlog/run_log_reader.h) returns, and the format constants.
//
// this module depends on core and scene/sim_state.h only: it knows nothing of MuJoCo, the
// pipeline or snapshots. a StepRecord is a SimState (scene/sim_state.h): its vectors are
// MuJoCo's, in its order and units; their sizes are those of RunLogLayout (dims()), and the
// codec writes and reads them in kStateFields order.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/scene/sim_state.h"

namespace penumbra {

/// the first 8 bytes of every run log: 0x89 'P' 'L' 'O' 'G' '\r' '\n' 0x1a (a high byte
/// first, so that no text tool mistakes a log for text; CR LF catches newline conversion).
inline constexpr std::array<uint8_t, 8> kRunLogMagic = {0x89, 'P', 'L', 'O', 'G', '\r', '\n', 0x1a};

/// the format version this build writes (u32 after the magic).
inline constexpr uint32_t kRunLogFormatVersion = 2;
/// the format versions this build reads.
inline constexpr std::array<uint32_t, 2> kRunLogReadableVersions = {1, 2};

/// what the state of a log of one format version holds: a step record is the first `fields`
/// rows of kStateFields (scene/sim_state.h; rows are only ever appended) and the header's
/// layout names the first `dims` StateDims; the dimensions after those count 0 and the fields
/// after those are empty when read.
struct RunLogStateShape {
  int fields = kNumStateFields;
  int dims = kNumStateDims;
};
/// the state shape of format `version`: 1 (MuJoCo 2.2.2's state: qpos ... userdata,
/// controller_next_update) 11 fields of 8 dimensions; 2 (MuJoCo 4's: history, eq_active,
/// plugin_state and plastic added) all of them.
constexpr RunLogStateShape RunLogStateShapeOf(uint32_t version) {
  constexpr RunLogStateShape kFormat1 = {static_cast<int>(StateField::kControllerNextUpdate) + 1,
                                         static_cast<int>(StateDim::kNumControllers) + 1};
  return version == 1 ? kFormat1 : RunLogStateShape{};
}
namespace run_log_format_detail {
// a version's fields are sized by that version's dimensions only
constexpr bool ShapeFieldsUseItsDims(uint32_t version) {
  const RunLogStateShape shape = RunLogStateShapeOf(version);
  for (int i = 0; i < shape.fields; ++i)
    if (static_cast<int>(kStateFields[i].dim) >= shape.dims) return false;
  return shape.fields <= kNumStateFields && shape.dims <= kNumStateDims;
}
}  // namespace run_log_format_detail
static_assert(run_log_format_detail::ShapeFieldsUseItsDims(1) &&
                  run_log_format_detail::ShapeFieldsUseItsDims(kRunLogFormatVersion),
              "RunLogStateShapeOf: a version's fields must be sized by its dimensions");

/// a run log could not be written or read: I/O failure, not a run log, another format version,
/// truncation or damage. messages name the file and, for damage, the chunk index and step.
class RunLogError : public Error {
 public:
  explicit RunLogError(const std::string& what) : Error(what) {}
};

/// one joint of the recorded model and where its coordinates are in qpos / qvel.
struct RunLogJoint {
  std::string name;    ///< MJCF name ("" for an unnamed joint)
  std::string type;    ///< "free", "ball", "slide" or "hinge"
  int qpos_adr = 0;    ///< first index in qpos
  int qpos_width = 0;  ///< entries in qpos (free 7, ball 4, slide/hinge 1)
  int qvel_adr = 0;    ///< first index in qvel (and every other field of size nv)
  int qvel_width = 0;  ///< entries in qvel (free 6, ball 3, slide/hinge 1)
};

/// the shape of the recorded state and the names that map it, so that a reader can find a
/// joint's, actuator's or body's values by name without the model.
struct RunLogLayout {
  int nq = 0;               ///< size of qpos
  int nv = 0;               ///< degrees of freedom (size of qvel and the other nv fields)
  int na = 0;               ///< size of act
  int nu = 0;               ///< size of ctrl
  int nmocap = 0;           ///< mocap bodies (mocap_pos has 3 nmocap entries, mocap_quat 4 nmocap)
  int nuserdata = 0;        ///< size of userdata
  int nbody = 0;            ///< bodies including the world (xfrc_applied has 6 nbody entries)
  int num_controllers = 0;  ///< size of controller_next_update
  int nhistory = 0;         ///< size of history (0 in a format 1 log)
  int neq = 0;              ///< equality constraints: size of eq_active (0 in a format 1 log)
  int npluginstate = 0;     ///< size of plugin_state (0 in a format 1 log)
  int nplastic = 0;         ///< size of plastic (0 in a format 1 log)
  std::vector<RunLogJoint> joints;            ///< (njnt) by MuJoCo joint id
  std::vector<std::string> actuator_names;    ///< (nu) by actuator id = index into ctrl
  std::vector<std::string> mocap_body_names;  ///< (nmocap) by mocap id
  std::vector<std::string> body_names;        ///< (nbody) by body id (0 = "world")
  std::vector<std::string> controller_names;  ///< (num_controllers) e.g. "go1: trot_gait"

  /// the counts above as the state table's dimensions (scene/sim_state.h).
  StateDims dims() const;
  /// sets the counts above from `dims`.
  void set_dims(const StateDims& dims);
};

/// a file the run read and its content hash (lowercase hex SHA-256 of its bytes).
struct RunLogAsset {
  std::string role;    ///< "world", "model", "mesh", "texture", "hfield", "include", ...
  std::string path;    ///< as the world or model names it, made absolute
  std::string sha256;  ///< 64 lowercase hex digits; "" when the file could not be read
  uint64_t size_bytes = 0;
};

/// everything known before the first step (the header chunk; JSON in the file).
struct RunLogHeader {
  /// the format version of the file (kRunLogFormatVersion when writing; set by the writer).
  uint32_t format_version = kRunLogFormatVersion;
  std::string penumbra_version;  ///< of the writer, e.g. "0.1.0"
  std::string mujoco_version;    ///< e.g. "4.0.0"
  /// the world file (absolute path) and its text; both "" for a bare model run
  /// (`penumbra run model.xml`), which then has model_file / model_text.
  std::string world_file;
  std::string world_text;
  /// for a bare model: the model file run (absolute path) and its text; else "".
  std::string model_file;
  std::string model_text;
  /// the composed MJCF the simulation compiled (composed.xml).
  std::string composed_mjcf;
  /// every file read to build the run: the world file, the model files and the meshes,
  /// textures and height fields the composed MJCF references.
  std::vector<RunLogAsset> assets;
  uint64_t seed = 0;
  std::string command_line;  ///< as typed, arguments joined by spaces
  double timestep_sec = 0;   ///< physics timestep; step n is at SimTimeOfStep(n, timestep_sec)
  RunLogLayout layout;
  bool has_sensor_records = false;  ///< the writer was asked for sensor records
  /// the adversity label of the run ("" = none), for information.
  std::string adversity;
};

/// the simulation state after `step` steps: a SimState (scene/sim_state.h), vectors in
/// MuJoCo's order and units, sizes from RunLogLayout::dims() (n = 0 entries allowed for an
/// empty model part; the fields a format 1 log does not hold are empty).
using StepRecord = SimState;

/// something that happened at a step besides the state: a command a bridge received, an
/// effect parameter change, a note. kind is free text ("command", "effect", "note", ...);
/// payload is JSON text (not checked by the log).
struct EventRecord {
  int64_t step = 0;
  double time_sec = 0;
  std::string kind;
  std::string payload;
};

/// one sensor output at a step (--record-sensors): a camera image, a LiDAR scan, IMU rows.
struct SensorRecord {
  int64_t step = 0;
  double time_sec = 0;
  std::string sensor;  ///< the sensor's name, e.g. "front" or "lidar0"
  /// what the payload is, e.g. "rgb.png", "depth.png", "segmentation.png", "points.pcd",
  /// "imu.csv" (the bytes the run's own writer produces for that output).
  std::string kind;
  std::string payload;  ///< bytes (binary)
};

/// one record of a log, in the order it was written within its stream.
using RunLogRecord = std::variant<StepRecord, EventRecord, SensorRecord>;

/// chunk kinds (u32 in the chunk header).
enum class RunLogChunkKind : uint32_t {
  kHeader = 1,   ///< the RunLogHeader as JSON (always chunk 0)
  kSteps = 2,    ///< StepRecords, steps increasing
  kEvents = 3,   ///< EventRecords
  kSensors = 4,  ///< SensorRecords
  kEnd = 5,      ///< the last chunk of a log closed cleanly (body: JSON summary)
};

/// lowercase name of a chunk kind ("header", "steps", ...), for messages.
std::string_view RunLogChunkKindName(RunLogChunkKind kind);

/// what a chunk header says (docs/run-log.md "Chunk"), plus where the chunk is in the file.
struct RunLogChunkInfo {
  RunLogChunkKind kind = RunLogChunkKind::kSteps;
  uint64_t index = 0;            ///< 0 for the header chunk, then 1, 2, ... in file order
  uint32_t record_count = 0;     ///< records in the body
  int64_t first_step = 0;        ///< smallest step of the records (0 if none)
  int64_t last_step = 0;         ///< largest step of the records (0 if none)
  uint64_t raw_size = 0;         ///< body bytes before compression
  uint64_t compressed_size = 0;  ///< body bytes in the file
  uint64_t file_offset = 0;      ///< offset of the chunk header in the file
};

/// lowercase hex SHA-256 of `bytes` (OpenSSL).
std::string Sha256Hex(std::string_view bytes);
/// lowercase hex SHA-256 of a file's bytes. @throws RunLogError naming the file if unreadable.
std::string Sha256OfFile(const std::string& path, uint64_t* size_bytes = nullptr);

}  // namespace penumbra
