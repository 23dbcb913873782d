#pragma once
// MJCF written for MuJoCo 3 read by MuJoCo 2.2.2: the keywords that Menagerie-era models
// use and 2.2.2 lacks. each is either rewritten into its 2.2.2 equivalent (with a warning
// naming the file and line) or rejected with a ConfigError that names the file, line and
// the usual 2.2.2 replacement. the table (one entry per keyword) is in mjcf_compat.cc;
// every keyword in the table was checked to be rejected by mj_loadXML of libmujoco 2.2.2
// (a one-element model each).
// internal to src/penumbra/compose.

#include <optional>
#include <string>
#include <vector>

#include "penumbra/compose/mjcf_source.h"

namespace penumbra::compose {

/// rewrites or rejects the MuJoCo-3 keywords of `src` (every element, includes expanded,
/// defaults included): <option integrator="implicitfast"> becomes "implicit", visual-only
/// attributes (<visual><global ellipsoidinertia>, ...) and solver/collision tuning that
/// 2.2.2 does not have (option ls_iterations, ...) are dropped, <light type> becomes
/// `directional`; one warning line each is appended to `warnings`.
/// @throws ConfigError(file, line, "<element>.<attribute>", ...) for keywords without a
///         faithful 2.2.2 form (position kv / dampratio / inheritrange, body gravcomp,
///         joint actuatorfrcrange, ...), saying what to write instead: ONE error for all of
///         them, naming the first (its file, line and key) and then every other one by file,
///         line and key ("(2) spot.xml:40: position.kv; (3) ..."), so that a model with
///         several is fixed in one pass.
void DowngradeMjcf3(const MjcfSource& src, std::vector<std::string>* warnings);

/// a hint for an MJCF element that MuJoCo 2.2.2 does not have but a newer MuJoCo does
/// (<frame>, <replicate>, <flexcomp>, <plugin>, ...), e.g. "<frame> is newer than MuJoCo
/// 2.2.2 (...); move its pos/quat into its children ..."; nullopt for other tags.
std::optional<std::string> NewerElementHint(const std::string& tag);

/// for a MuJoCo 2.2.2 load error message ("Schema violation: unrecognized attribute:
/// 'x'", "invalid keyword: 'y'"): a sentence saying that the attribute or keyword is not
/// MuJoCo 2.2.2's and, when known, the replacement; nullopt when the message is of
/// another kind.
std::optional<std::string> HintForMujocoError(const std::string& message);

}  // namespace penumbra::compose
