// A scene: one TOML file that says what to simulate (docs/user-guide.md, "Scene reference").
// Reading it validates every key; a bad scene raises SceneError whose message
// is one line naming the file and the key. The story of the reading is here;
// what a scene holds is schema.h's, and the tables' readers are
// physics_input.h, fault_input.h and run_input.h.
#pragma once

#include "scene/input.h"
#include "scene/schema.h"

#include <mpi.h>

#include <string>
#include <vector>

namespace biotcontact
{

/// The message of the lowest rank whose `message` is not empty, or an empty
/// string when none has one (collective).
std::string agreed_error(const std::string& message, MPI_Comm comm);

/// Bad input found on some ranks only (a value at their own nodes): every
/// rank throws SceneError with the message of the lowest rank that found
/// one, so that no rank is left waiting in a collective call. Does nothing
/// when `message` is empty on every rank (collective).
void agree_on_error(const std::string& message, MPI_Comm comm);

/// Reads and validates a scene; `overrides` are "key.path=value" strings
/// applied to the TOML document before validation.
Scene read_scene(const std::string& file, const std::vector<std::string>& overrides = {});

} // namespace biotcontact
