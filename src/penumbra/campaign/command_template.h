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
//   - a method that needs a shell writes one: `sh -c 'SCRIPT' sh {dataset} {output}`. the
//     script may not hold a placeholder (that would splice a value into shell text); values
//     are passed as its positional arguments and read as "$1", "$2", ... the same holds for
//     the inline program of python* -c and perl / ruby / node -e.
// {name} placeholders and the {{ }} brace escapes are left in the words and filled per job.

#include <map>
#include <string>
#include <vector>

namespace penumbra {

/// `text` split into words by the grammar of the file comment; placeholders stay in them.
/// @throws ConfigError("", 0, "", problem) naming the refused character and its 1-based column
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
