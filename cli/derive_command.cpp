// quadgen derive VEHICLE.yaml --out DIR [--effects e1,e2|all] [--params fitted_parameters.yaml]
#include <chrono>
#include <iostream>
#include <set>

#include "audit.hpp"
#include "commands.hpp"
#include "dynamics.hpp"
#include "effects.hpp"
#include "fitted_parameters.hpp"
#include "geometry.hpp"
#include "header_writer.hpp"
#include "output_set.hpp"
#include "report.hpp"
#include "thesis_reference.hpp"
#include "vehicle.hpp"

namespace quadgen::cli {

void add_derive(CLI::App& app, DeriveArgs& args) {
  CLI::App* c = app.add_subcommand("derive", "derive, audit and emit the flight model of a vehicle");
  c->add_option("vehicle", args.vehicle, "vehicle description (YAML)")->required();
  c->add_option("--out", args.out, "output directory")->required();
  std::string effect_names;  // the catalogue, so --help lists what --effects accepts
  for (const Effect& e : effect_catalogue()) effect_names += (effect_names.empty() ? "" : ", ") + e.name;
  c->add_option("--effects", args.effects, "comma-separated effects to add, or 'all': " + effect_names);
  c->add_option("--params", args.params,
                "fitted_parameters.yaml written by diagnose: the model gets its effects and its fitted values as "
                "nominal values (the fitted model, regenerated)");
}

int run_derive(const DeriveArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const Vehicle vehicle = load_vehicle(args.vehicle);
  output::OutputDirectory out(args.out, {args.vehicle, args.params});  // refused before the work, not after
  DeriveOptions opt;
  opt.effects = parse_effect_list(args.effects);
  FittedParameters fitted;
  if (!args.params.empty()) {
    fitted = load_fitted_parameters(args.params);
    if (args.effects.empty()) opt.effects = fitted.effects;
    else if (std::set<std::string>(opt.effects.begin(), opt.effects.end()) !=
             std::set<std::string>(fitted.effects.begin(), fitted.effects.end()))
      throw std::invalid_argument("--effects differs from the effects " + args.params + " was fitted with; leave it out");
  }
  std::cerr << "[1/5] mass properties of " << vehicle.blocks.size() << " blocks\n";
  const MassProperties mp = derive_mass_properties(vehicle);
  std::cerr << "[2/5] equations of motion and Jacobians\n";
  SymbolicModel model = derive_model(vehicle, mp, opt);
  if (!args.params.empty()) apply_fitted_parameters(model, fitted);
  std::cerr << "[3/5] audit\n";
  const AuditResult result = audit(model, mp);
  std::vector<ThesisItem> thesis;
  if (vehicle.name == "finken3") thesis = compare_with_thesis(model, mp);
  std::cerr << "[4/5] generating C++\n";
  emission::EmitOptions eo;
  eo.vehicle_file = args.vehicle;
  eo.effects_flag = args.params.empty() ? (args.effects.empty() ? "" : " --effects " + args.effects)
                                        : " --params " + args.params;
  if (!args.params.empty()) eo.parameter_source = "fitted values from " + args.params;
  const emission::GeneratedHeader header = emission::generate_header(model, eo);
  std::cerr << "[5/5] writing " << args.out << "\n";
  const Derivation d{vehicle, mp, model, result, thesis};
  out.add("model.json", model_json(d));
  out.add("derivation.md", derivation_markdown(d));
  out.add("model.hpp", header.content);
  out.commit();
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "derived " << vehicle.name << ": " << model.states.size() << " states, " << model.inputs.size()
            << " inputs, " << model.params.size() << " parameters; audit "
            << (result.all_passed() ? "passed" : "FAILED") << " (" << result.checks.size() << " checks); "
            << secs << " s\n"
            << "generated model.hpp (" << header.name << "): f " << header.ops_f_before << " -> " << header.ops_f_after
            << " ops, f + Jacobians " << header.ops_before << " -> " << header.ops_after << " ops after CSE, "
            << header.pre_count << " precomputed values (" << header.pre_ops << " ops)\n";
  return result.all_passed() ? 0 : 3;
}

}  // namespace quadgen::cli
