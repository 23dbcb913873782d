#include "penumbra/app/tool_commands.h"

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/app/backend_flag.h"
#include "penumbra/app/cli_options.h"
#include "penumbra/app/contact_sheet.h"
#include "penumbra/app/heightfield_tool.h"
#include "penumbra/app/npc_map_command.h"
#include "penumbra/app/vdb_tool.h"

namespace penumbra {
namespace {

class HeightfieldCommand : public Command {
 public:
  std::string name() const override { return "heightfield"; }
  std::string summary() const override {
    return "a world's static geometry sampled from above into a MuJoCo hfield model";
  }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("world", options_.world_file, "world file")->required();
    verb->add_option("--model", options_.model,
                     "sample only this model's static geoms (default: the ground)");
    verb->add_option("--geoms", options_.geoms,
                     "sample only static geoms whose name (model/geom) matches one of these "
                     "globs (default: the ground: planes, height fields, geoms named *floor*, "
                     "*ground*, *terrain*)")
        ->delimiter(',');
    verb->add_flag("--all", options_.all,
                   "sample every static geom (trees, rocks, furniture and walls included)");
    AddDecimal(
        verb, "--cell", [this](double v) { options_.cell_m = v; }, 0, true,
        "sample spacing, m (default 0.1)");
    verb->add_option("--extent", extent_,
                     "plan rectangle x0,y0,x1,y1 in m (default: the geometry's bounds)")
        ->delimiter(',')
        ->expected(4);
    verb->add_option("--out,-o", options_.out_dir, "output folder (default .)");
    verb->add_option("--name", options_.name, "file stem (default: the model's name, or terrain)");
  }

  int Run(const CommandArgs&) override {
    if (!extent_.empty()) options_.extent = {extent_[0], extent_[1], extent_[2], extent_[3]};
    return RunHeightField(options_);
  }

 private:
  HeightFieldOptions options_;
  std::vector<double> extent_;
};

class ContactSheetCommand : public Command {
 public:
  std::string name() const override { return "contact-sheet"; }
  std::string summary() const override {
    return "one instant of a world under adversity presets, side by side, as a PNG";
  }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("--world", options_.worlds,
                     "world file, one row each; repeat for more rows (default: bundled default "
                     "world)");
    verb->add_option("--presets", options_.presets, "presets, left to right")->delimiter(',');
    AddDecimal(
        verb, "--time", [this](double v) { options_.time_sec = v; }, 0, false,
        "sim time of the frames, s");
    AddInteger(verb, "--width", &options_.width, 16, 4096, "frame width");
    AddInteger(verb, "--height", &options_.height, 16, 4096, "frame height");
    verb->add_option("--out,-o", options_.out, "output PNG (default docs/effects.png)");
    AddInteger(verb, "--threads", &options_.threads, 0, 256, "render threads (0 = all cores)");
    backend_.Add(verb, "each world's render.backend");
  }

  int Run(const CommandArgs&) override {
    options_.backend = backend_.Resolve();
    return MakeContactSheet(options_);
  }

 private:
  ContactSheetOptions options_;
  BackendFlag backend_;
};

class NpcMapCommand : public Command {
 public:
  std::string name() const override { return "npc-map"; }
  std::string summary() const override {
    return "the walkable map of a world's NPCs (people, vehicles, areas, lanes) as a PNG";
  }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("world", options_.world_file, "world file")->required();
    verb->add_option("--out,-o", options_.out, "output PNG (default npc_map.png)");
    verb->add_flag("--force", options_.force, "replace --out if it exists");
    verb->add_option("--adversity", options_.adversity,
                     "adversity preset whose crowd to place (default: the world's own)");
    AddInteger(verb, "--pixels", &options_.pixels_per_cell, 1, 16,
               "pixels per 0.1 m cell (default 4)");
  }

  int Run(const CommandArgs&) override { return WriteNpcMap(options_); }

 private:
  NpcMapOptions options_;
};

class MakeVdbCommand : public Command {
 public:
  std::string name() const override { return "make-vdb"; }
  std::string summary() const override {
    return "write a procedural smoke cloud as an OpenVDB file (float grid 'density')";
  }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("file", path_, "output .vdb file")->required();
    AddUint64(verb, "--seed", &seed_, "blob layout seed");
    AddDecimal(
        verb, "--voxel", [this](double v) { options_.voxel_m = v; }, 0, true, "voxel size, m");
    AddDecimal(
        verb, "--radius", [this](double v) { options_.radius_m = v; }, 0, true, "cloud radius, m");
    AddInteger(verb, "--blobs", &options_.blobs, 1, 64, "Gaussian puffs");
  }

  int Run(const CommandArgs&) override {
    if (seed_) options_.seed = *seed_;
    spdlog::info("{}", DescribeSmokeVdb(MakeSmokeVdb(path_, options_)));
    return 0;
  }

 private:
  std::string path_;
  SmokeVdbOptions options_;
  std::optional<uint64_t> seed_;
};

}  // namespace

std::unique_ptr<Command> MakeHeightfieldCommand() { return std::make_unique<HeightfieldCommand>(); }
std::unique_ptr<Command> MakeContactSheetCommand() {
  return std::make_unique<ContactSheetCommand>();
}
std::unique_ptr<Command> MakeNpcMapCommand() { return std::make_unique<NpcMapCommand>(); }
std::unique_ptr<Command> MakeMakeVdbCommand() { return std::make_unique<MakeVdbCommand>(); }

}  // namespace penumbra
