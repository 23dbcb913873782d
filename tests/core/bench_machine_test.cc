#include "penumbra/core/bench_machine.h"

#include <gtest/gtest.h>

#include <string>

namespace penumbra {
namespace {

TEST(BenchMachineTest, ReadsTheCpuModelAndGpuModelFromTheirFiles) {
  const std::string cpuinfo =
      "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC 7B13\nflags\t\t: fpu\n\n"
      "processor\t: 1\nmodel name\t: other\n";
  EXPECT_EQ(CpuModelFromCpuinfo(cpuinfo), "AMD EPYC 7B13");
  EXPECT_EQ(CpuModelFromCpuinfo("processor\t: 0\n"), "");
  const std::string information =
      "Model: \t\t NVIDIA H200\nIRQ:             16\nGPU UUID: \t GPU-1234\n";
  EXPECT_EQ(GpuModelFromNvidiaInformation(information), "NVIDIA H200");
  EXPECT_EQ(GpuModelFromNvidiaInformation(""), "");
}

TEST(BenchMachineTest, DescribesCoresCpuAndGpus) {
  EXPECT_EQ(BenchTargetMachine().Describe(), "2 cores, AMD EPYC, no GPU");
  const MachineInfo big{16, "Intel(R) Xeon(R) Platinum 8480C", {"NVIDIA H200", "NVIDIA H200"}};
  EXPECT_EQ(big.Describe(),
            "16 cores, Intel(R) Xeon(R) Platinum 8480C, GPU NVIDIA H200 + NVIDIA H200");
  EXPECT_EQ(BenchTargetLabel(), "target on 2 cores, AMD EPYC, no GPU");
}

TEST(BenchMachineTest, JudgesATargetOnlyOnTheMachineItWasSetOn) {
  const MachineInfo same = BenchTargetMachine();
  EXPECT_EQ(BenchTargetVerdict(true, same), "met");
  EXPECT_EQ(BenchTargetVerdict(false, same), "NOT met");
  // a bigger machine meeting the number, a smaller one missing it: neither is a verdict
  for (const MachineInfo& other :
       {MachineInfo{16, "AMD EPYC", {"NVIDIA H200"}}, MachineInfo{4, "AMD EPYC", {}},
        MachineInfo{2, "Intel(R) Core(TM) i5", {}}}) {
    for (bool met : {true, false}) {
      const std::string v = BenchTargetVerdict(met, other);
      EXPECT_EQ(v, "not judged (set on 2 cores, AMD EPYC, no GPU; this machine: " +
                       other.Describe() + ")");
    }
  }
}

TEST(BenchMachineTest, ThisMachineHasCoresAndACpuModel) {
  const MachineInfo here = ThisMachine();
  EXPECT_GE(here.cores, 1);
#if defined(__x86_64__)
  EXPECT_FALSE(here.cpu_model.empty());  // x86 Linux names every CPU's model in /proc/cpuinfo
#endif
  EXPECT_TRUE(SameMachine(here, here));
}

}  // namespace
}  // namespace penumbra
