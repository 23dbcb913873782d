#pragma once
// the machine a benchmark runs on and the machine its targets were set on. a frames/s or
// milliseconds target is a number measured on one machine: `penumbra bench` judges a target
// (met / NOT met) only on the machine it was set on, and elsewhere prints the measurement
// with both machines named instead of a verdict.

#include <string>
#include <vector>

namespace penumbra {

/// what a benchmark's absolute numbers depend on.
struct MachineInfo {
  int cores = 0;                  ///< logical CPUs this process may run on
  std::string cpu_model;          ///< the first CPU's model name; "" when unknown
  std::vector<std::string> gpus;  ///< NVIDIA GPU models; empty = none found
  /// e.g. "2 cores, AMD EPYC, no GPU" or "16 cores, Intel(R) Xeon(R) ..., GPU NVIDIA H200".
  std::string Describe() const;
};

/// this machine: cores from the process's CPU affinity (else std::thread's count), the CPU
/// model from /proc/cpuinfo's first "model name", GPUs from the NVIDIA driver's
/// /proc/driver/nvidia/gpus/*/information "Model:" lines (no driver = no GPU). never throws:
/// what cannot be read stays empty.
MachineInfo ThisMachine();

/// the first "model name" value of /proc/cpuinfo text (trimmed); "" when there is none.
std::string CpuModelFromCpuinfo(const std::string& cpuinfo);
/// the "Model:" value of an NVIDIA driver information file (trimmed); "" when there is none.
std::string GpuModelFromNvidiaInformation(const std::string& information);

/// the machine the bench targets were set on (docs/performance.md): the 2-core development
/// machine, 2 cores, AMD EPYC, no GPU.
const MachineInfo& BenchTargetMachine();

/// true when `a` and `b` have the same core count, CPU model and GPUs.
bool SameMachine(const MachineInfo& a, const MachineInfo& b);

/// "target on <BenchTargetMachine().Describe()>": how a target line names its machine.
std::string BenchTargetLabel();

/// the verdict printed after a target: "met" / "NOT met" when `here` is the target machine;
/// otherwise "not judged (set on <target>; this machine: <here>)", since a number of one
/// machine says nothing of another.
std::string BenchTargetVerdict(bool met, const MachineInfo& here);

}  // namespace penumbra
