// The actuator's Eq. 3 parameters refined against the loop's exact sampled response (docs/
// identification.md, "Actuator"). The continuous fit (identify/actuator_fit.hpp) treats the loop's
// sample-and-hold as 1.5 periods of delay; with an acceleration output that is not exact: the part of
// the acceleration that follows the held force step at once (the residue form's b terms, the actuator's
// feedthrough) is sampled a whole period late, the smooth part half a period, so the continuous fit
// reads up to half a period too little delay at the top of the band. Here the measured acceleration
// per volt is matched by the exactly discretised plant (analysis::LoopModel::plant_response: zero-order
// hold, the fractional delay, the configured sensor's sampled coupling and the one-period output latch)
// built from the identified structure and a candidate actuator; Levenberg-Marquardt (Eigen) on the
// relative error, from the continuous fit. Off the real-time path; about a hundred plant discretisations.
#pragma once

#include "analysis/spectral.hpp"
#include "config/config.hpp"
#include "identify/actuator_fit.hpp"

namespace robodamp::identify {

// structure: a configuration holding the identified robot (its actuator values are replaced); the
// chirp's acceleration per volt at structure.sensor. Points: those the continuous fit used.
[[nodiscard]] ActuatorFit refine_actuator_discrete(const ActuatorFit& start,
                                                   const analysis::FrfEstimate& accel_per_volt,
                                                   const config::Config& structure);

// The sampled acceleration per volt the loop records (sensor included, output latch included) for a
// configuration, at f.
[[nodiscard]] Complex recorded_accel_per_volt(const config::Config& cfg, double f_hz);

}  // namespace robodamp::identify
