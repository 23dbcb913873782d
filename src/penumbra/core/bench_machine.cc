#include "penumbra/core/bench_machine.h"

#include <sched.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

namespace penumbra {
namespace {

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

// the value of the first line "<key><spaces>: value" of `text`; "" when there is none
std::string FieldValue(const std::string& text, const std::string& key) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    if (Trim(line.substr(0, colon)) == key) return Trim(line.substr(colon + 1));
  }
  return "";
}

// the first 64 KiB of a file; "" when it cannot be read
std::string ReadSmallFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::string text(64 * 1024, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(in.gcount()));
  return text;
}

}  // namespace

std::string MachineInfo::Describe() const {
  std::string out = std::to_string(cores) + (cores == 1 ? " core, " : " cores, ") +
                    (cpu_model.empty() ? "unknown CPU" : cpu_model);
  if (gpus.empty()) return out + ", no GPU";
  for (size_t i = 0; i < gpus.size(); ++i) out += (i == 0 ? ", GPU " : " + ") + gpus[i];
  return out;
}

std::string CpuModelFromCpuinfo(const std::string& cpuinfo) {
  return FieldValue(cpuinfo, "model name");
}

std::string GpuModelFromNvidiaInformation(const std::string& information) {
  return FieldValue(information, "Model");
}

MachineInfo ThisMachine() {
  MachineInfo m;
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) m.cores = CPU_COUNT(&set);
  if (m.cores <= 0) m.cores = static_cast<int>(std::thread::hardware_concurrency());
  m.cpu_model = CpuModelFromCpuinfo(ReadSmallFile("/proc/cpuinfo"));
  std::error_code ec;
  std::vector<std::filesystem::path> gpu_dirs;
  for (std::filesystem::directory_iterator it("/proc/driver/nvidia/gpus", ec), end;
       !ec && it != end; it.increment(ec))
    gpu_dirs.push_back(it->path());
  std::sort(gpu_dirs.begin(), gpu_dirs.end());
  for (const auto& dir : gpu_dirs) {
    const std::string model = GpuModelFromNvidiaInformation(ReadSmallFile(dir / "information"));
    if (!model.empty()) m.gpus.push_back(model);
  }
  return m;
}

const MachineInfo& BenchTargetMachine() {
  static const MachineInfo machine{2, "AMD EPYC", {}};
  return machine;
}

bool SameMachine(const MachineInfo& a, const MachineInfo& b) {
  return a.cores == b.cores && a.cpu_model == b.cpu_model && a.gpus == b.gpus;
}

std::string BenchTargetLabel() { return "target on " + BenchTargetMachine().Describe(); }

std::string BenchTargetVerdict(bool met, const MachineInfo& here) {
  if (SameMachine(here, BenchTargetMachine())) return met ? "met" : "NOT met";
  return "not judged (set on " + BenchTargetMachine().Describe() +
         "; this machine: " + here.Describe() + ")";
}

}  // namespace penumbra
