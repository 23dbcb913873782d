#pragma once
// the world readers' old names, kept for the files outside world/ that still say YamlReader or
// include this header (benchmark/, session/, app/, replay/: other helpers' zones this session).
// new code includes penumbra/config/param_reader.h (ParamReader) and
// penumbra/config/yaml_document.h (ParseYaml, RefuseYamlTags) instead. no yaml-cpp here.

#include "penumbra/config/param_reader.h"
#include "penumbra/config/yaml_document.h"

namespace penumbra {

/// ParamReader under its old name.
using YamlReader = ParamReader;

}  // namespace penumbra
