#include "solvers/options.h"

namespace biotcontact
{

std::string system_name(const std::string& prefix) { return "the " + prefix.substr(0, prefix.size() - 1); }

} // namespace biotcontact
