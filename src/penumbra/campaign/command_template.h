#pragma once
// a benchmark method's command template (`command:` of a spec, docs/benchmarks.md "Command
// templates") and how it becomes a process's argument vector without a shell. the template is
// split into words once, when the spec is loaded; each job substitutes its {placeholders}
// inside each word as plain text, so a value (a path holding spaces, quotes, `$(...)` or `;`)
// stays one argument and is never read by a shell. the process is started with execvp
// (campaign/child_process.h), never through /bin/sh.
//
// the word grammar, a small subset of the POSIX shell's that means the same under /bin/sh:
//   - blanks (space, tab) separate words; trailing newlines are ignored;
//   - '...' groups everything up to the next ' literally;
//   - "..." groups; inside it \" \\ \$ \` stand for the character, any other \ is literal;
//   - outside quotes, \c stands for the character c;
//   - nothing is expanded: an unquoted ; & | < > ( ) $ ` * ? [ , a # or ~ that begins a word,
//     a newline or another control character, an unescaped $ or ` inside "...", an
//     unterminated quote or a trailing \ is refused (quote it for the literal character);
//   - the first word may not be a variable assignment (NAME=value: write `/usr/bin/env
//     NAME=value PROGRAM ...`) or a shell builtin or keyword (exec, cd, export, ...);
//   - braces: {name} is a placeholder, {{ and }} are literal braces, a lone brace is refused.
// where a placeholder may stand (so that a value is one argument a program receives, never
// text a shell or an interpreter parses):
//   - a word holding a placeholder holds nothing else but letters, digits and _ - . / , : + = @ %
//     (a whole argument `{output}`, or a fixed prefix or suffix: `--out={output}`,
//     `{dataset}/rgb.txt`, `{fx},{fy}`); two placeholders need a character between them. a
//     placeholder in a text with blanks, quotes, brackets or literal braces (a script, code, a
//     JSON document) is refused;
//   - every word naming a shell (sh, bash, dash, zsh, ksh, fish, csh, ...) or an interpreter
//     (python*, pypy*, perl*, ruby*, node, php*, lua*, Rscript, osascript, julia*, tclsh, awk,
//     sed, env -S), wherever it stands (after env, nice, timeout, stdbuf, xargs, find -exec,
//     ...), starts a program that reads code: its options and its program (the script of
//     sh -c, python -c, perl / ruby / node -e, the awk or sed program, a script file, a python
//     -m module) hold no placeholder; the words after the program are its arguments and may.
//     the word after a shell's -c script is its $0 name. after python -m MODULE for a module
//     that runs its arguments as code or as a program (timeit, pdb, cProfile, profile, trace,
//     code, runpy, doctest, ...) no word holds a placeholder;
//   - after a program that hands its arguments to a shell as text (ssh, watch, su, runuser,
//     sudo, doas, script, flock, tmux, screen, make, parallel, pwsh, expect, gdb) no word holds
//     a placeholder. these names are matched on every word (a value such as `--lang python`
//     is read as the program: write `--lang=python`).
//   a method that needs a shell writes `sh -c 'SCRIPT' sh {dataset} {output}` and reads the
//   values as "$1", "$2", ...; python3 -c 'CODE' {dataset} reads sys.argv[1].
// {name} placeholders and the {{ }} brace escapes are left in the words and filled per job.

#include <map>
#include <string>
#include <vector>

namespace penumbra {

/// `text` split into words by the grammar of the file comment, and checked against the
/// placeholder rules there; placeholders stay in the words.
/// @throws ConfigError("", 0, "", problem) naming the refused character or word and its 1-based
///         column
///         (the spec loader re-raises it at the `command` field's file and line).
std::vector<std::string> SplitCommandTemplate(const std::string& text);

/// `text` with each `{key}` replaced by values.at(key) as plain text (`{{` / `}}` become braces).
/// @throws Error for a placeholder not in `values` (templates are checked at spec load).
std::string FillTemplate(const std::string& text, const std::map<std::string, std::string>& values);

/// the argument vector of a split template: FillTemplate applied to every word; each word
/// stays exactly one argument whatever the values hold.
/// @throws Error as FillTemplate.
std::vector<std::string> ExpandCommandTemplate(const std::vector<std::string>& words,
                                               const std::map<std::string, std::string>& values);

}  // namespace penumbra
