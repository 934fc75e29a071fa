// The one estimate shape every JSON output uses (output/estimate.hpp, docs/formats.md):
// value, unit, ci95 [lower|null, upper|null], identifiability (string or null), at_bound.
#pragma once
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace quadgen::test {

inline ::testing::AssertionResult has_estimate_shape(const nlohmann::json& e) {
  auto fail = [&](const std::string& why) { return ::testing::AssertionFailure() << why << " in " << e.dump(); };
  if (!e.is_object()) return fail("not an object");
  if (!e.contains("value") || !(e["value"].is_number() || e["value"].is_null())) return fail("no numeric value");
  if (!e.contains("unit") || !e["unit"].is_string()) return fail("no unit");
  if (!e.contains("ci95") || !e["ci95"].is_array() || e["ci95"].size() != 2) return fail("no two-sided ci95");
  for (const auto& side : e["ci95"])
    if (!side.is_number() && !side.is_null()) return fail("a ci95 side neither number nor null");
  if (e["ci95"][0].is_number() && e["ci95"][1].is_number() && e["ci95"][0].get<double>() > e["ci95"][1].get<double>())
    return fail("ci95 sides reversed");
  if (!e.contains("identifiability") || !(e["identifiability"].is_string() || e["identifiability"].is_null()))
    return fail("no identifiability");
  if (!e.contains("at_bound") || !e["at_bound"].is_boolean()) return fail("no at_bound");
  return ::testing::AssertionSuccess();
}

}  // namespace quadgen::test
