#pragma once
// the `penumbra` command line: `penumbra run`, `penumbra bench render|physics`.

namespace penumbra {

/// parses argv and runs the verb; returns the process exit code
/// (0 ok, 1 runtime failure, 2 bad input). never throws.
int RunCli(int argc, char** argv);

}  // namespace penumbra
