// A flight log read for a vehicle: the log through its mapping (fit/log_reader.hpp), its
// samples with the vehicle's rotors (fit/flight_data.hpp), and what the log's own
// configuration says about those rotors. The one path fit, predict and diagnose read a log by.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "fit/flight_data.hpp"
#include "model/vehicle.hpp"

namespace quadgen::fit {

// read_log + load_flight with the vehicle's rotors, and logged_rotor_notes among the flight's
// notes. Throws the readers' errors (FitError, runtime::LogError) unchanged.
Flight read_flight(const std::string& path, const ColumnMapping* mapping, double resample_hz, const Vehicle& v);
// The same with the mapping's file (empty: none).
Flight read_flight(const std::string& path, const std::string& mapping_path, double resample_hz, const Vehicle& v);

// PX4 records in a ULog where each motor sits and which way it spins (CA_ROTOR_COUNT,
// CA_ROTORn_PX / _PY / _KM: motor n + 1, forward-right-down, KM > 0 counter-clockwise seen
// from above; since v1.14's control allocation) and which output channel drives which motor
// (the output functions PWM_MAIN_FUNCn, PWM_AUX_FUNCn, UAVCAN_EC_FUNCn, ...: 101 is motor 1,
// n counts channels from 1). A vehicle file that numbers its rotors otherwise than the
// mapping's u_ columns read them gives a model whose motors push at the wrong places, which
// every fit then absorbs into something else (issue #14 asks for exactly this check).
//
// One note per u_ column whose logged motor sits nearer another of the vehicle file's rotors
// (by its direction from the CoG, the file's rotors' from their centre) or spins the other way,
// one for a column whose channel's function is no motor or a motor beyond the count, and one if
// the log counts other rotors than the file. A motor whose place is PX4's default (0, 0) is
// not judged. A motor is known for `actuator_motors.control[k]` (motor k + 1)
// and for `actuator_outputs[i].output[c]` where the log's output functions give channel c + 1
// one motor; where two families give it different motors (which driver logged instance i the
// log does not say) or none, that column is not judged. Empty without the parameters (CSV
// and uSD logs, PX4 before v1.14) or where all agree.
std::vector<std::string> logged_rotor_notes(const std::string& path, const std::map<std::string, double>& parameters,
                                            const ColumnMapping& mapping, const Vehicle& v);

}  // namespace quadgen::fit
