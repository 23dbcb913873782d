#pragma once
// runs a SimLoop as a harness for a source or sink under test.

#include <initializer_list>

#include "penumbra/pipeline/sim_loop.h"

namespace penumbra::testing {

/// runs `source` with `sinks` (added in order) until the simulated time reaches
/// `end_time_sec` (SimLoopOptions::end_time_sec), an error or the source's end; returns how
/// the loop ended.
inline LoopFinish RunLoop(Source* source, std::initializer_list<Sink*> sinks, double end_time_sec) {
  SimLoopOptions o;
  o.end_time_sec = end_time_sec;
  SimLoop loop(source, o);
  for (Sink* s : sinks) loop.AddSink(s);
  return loop.Run();
}

}  // namespace penumbra::testing
