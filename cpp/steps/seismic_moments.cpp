#include "steps/seismic_moments.h"

namespace biotcontact
{

SeismicMoments moments_of(const ContactSet& set)
{
  SeismicMoments moments;
  for (std::size_t b = 0; b < set.boundaries.size(); ++b)
    if (set.faults[b])
      moments.names.push_back(set.boundaries[b]);
  return moments;
}

void record_moments(SeismicMoments& moments, double t, const ContactState& state)
{
  moments.steps.push_back(t);
  for (const FaultSummary& f : state.faults)
    moments.steps.push_back(f.moment);
}

void keep_moments(const SeismicMoments& moments, std::map<std::string, std::vector<double>>& arrays)
{
  if (!moments.steps.empty())
    arrays["seismic_moments"] = moments.steps;
}

void restore_moments(SeismicMoments& moments, const std::map<std::string, std::vector<double>>& arrays)
{
  if (const auto found = arrays.find("seismic_moments"); found != arrays.end())
    moments.steps = found->second;
}

} // namespace biotcontact
