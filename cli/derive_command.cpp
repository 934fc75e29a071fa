// quadgen derive VEHICLE.yaml --out DIR [--effects e1,e2|all] [--params fitted_parameters.yaml]
#include <chrono>
#include <iostream>

#include "cli/derive_command.hpp"
#include "output/sinks.hpp"
#include "app/derive_pipeline.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/output_set.hpp"

namespace quadgen::cli {

void add_derive(CLI::App& app, DeriveArgs& args) {
  CLI::App* c = app.add_subcommand("derive", "derive, audit and emit the flight model of a vehicle");
  c->add_option("vehicle", args.vehicle, "vehicle description (YAML)")->required();
  c->add_option("--out", args.out, "output directory")->required();
  const std::string effect_names = catalogue_names();  // --help lists what --effects accepts
  c->add_option("--effects", args.effects, "comma-separated effects to add, or 'all': " + effect_names);
  c->add_option("--params", args.params,
                "fitted_parameters.yaml written by diagnose: the model gets its effects and its fitted values as "
                "nominal values (the fitted model, regenerated)");
}

int run_derive(const DeriveArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const Vehicle vehicle = load_vehicle(args.vehicle);
  output::OutputDirectory out(args.out, "derive", {args.vehicle, args.params});  // refused before the work, not after
  DeriveRequest request;
  request.derive.effects = parse_effect_list(args.effects);
  request.emit.vehicle_file = args.vehicle;
  request.emit.effects_flag = args.effects.empty() ? "" : " --effects " + args.effects;
  // The fitted values: --params, or the vehicle file's own `fitted:` section.
  use_fitted_values(request, vehicle, args.vehicle, args.params, !args.effects.empty());
  std::cerr << "[1/5] mass properties of " << vehicle.blocks.size() << " blocks\n";
  const MassProperties mass_properties = derive_mass_properties(vehicle);
  int step = 1;
  request.progress = [&](const std::string& what) { std::cerr << "[" << ++step << "/5] " << what << "\n"; };
  const DerivedModel d = run_derive_pipeline(vehicle, mass_properties, request);
  std::cerr << "[5/5] writing " << output::printable(args.out) << "\n";
  out.add("model.json", d.model_json);
  out.add("derivation.md", d.derivation_md);
  out.add("model.hpp", d.header.content);
  out.commit();
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const SymbolicModel& model = d.model;
  const codegen::GeneratedHeader& header = d.header;
  std::cout << "derived " << vehicle.name << ": " << model.states.size() << " states, " << model.inputs.size()
            << " inputs, " << model.params.size() << " parameters; audit "
            << (d.audit.all_passed() ? "passed" : "FAILED") << " (" << d.audit.checks.size() << " checks); " << secs
            << " s\n"
            << "generated model.hpp (" << header.name << "): f " << header.ops_f_before << " -> " << header.ops_f_after
            << " ops, f + Jacobians " << header.ops_before << " -> " << header.ops_after << " ops after CSE, "
            << header.pre_count << " precomputed values (" << header.pre_ops << " ops)\n";
  // What a user checks first against their scale and CAD (values as the model uses them:
  // from the blocks, or measured values the vehicle file gives in `derived:`).
  const auto nominal = [&](const std::string& name) { return model.params[model.param_index(name)].nominal; };
  std::cout << "mass " << nominal("mass") << " kg; centre of gravity (" << nominal("cog_x") << ", " << nominal("cog_y")
            << ", " << nominal("cog_z") << ") m; inertia J_xx, J_yy, J_zz " << nominal("J_xx") << ", " << nominal("J_yy")
            << ", " << nominal("J_zz") << " kg m^2\n";
  return d.audit.all_passed() ? 0 : 3;
}

}  // namespace quadgen::cli
