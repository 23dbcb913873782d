#pragma once
// the `penumbra` command line: `penumbra run`, `penumbra replay`, `penumbra bench render|physics`.

namespace penumbra {

/// parses argv and runs the verb; returns the process exit code: 0 ok (also --help and
/// --version, printed on stdout), 1 runtime failure, 2 bad input or usage (every CLI11 parse
/// error; message on stderr), 3 for a `replay --resimulate` that diverged from its log,
/// 128 + signal (130 SIGINT, 143 SIGTERM) for a `run` or `replay` stopped by a signal after
/// writing its outputs. logs and errors go to stderr. during `run`, SIGINT and
/// SIGTERM handlers are installed (the first stops at the next physics step, a second exits
/// at once). never throws.
int RunCli(int argc, char** argv);

}  // namespace penumbra
