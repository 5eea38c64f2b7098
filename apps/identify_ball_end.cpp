// `robodamp identify cutting --ball-end`: the shear coefficients of a ball-end mill as polynomials in the
// axial angle and the edge coefficients, from slot-milling mean forces (the ball-end bone study's method; identify/
// ball_end.hpp, docs/identification.md); the report is identify/ball_end_report.hpp's.
#include <cstdio>
#include <fstream>
#include <iostream>

#include "apps/identify_command.hpp"
#include "identify/ball_end.hpp"
#include "identify/ball_end_report.hpp"

namespace robodamp::apps {

int run_identify_ball_end(const IdentifyArgs& a) {
  if (a.csv_path.empty() || a.teeth == 0 || a.diameter_mm == 0.0) {
    std::cerr << "robodamp identify cutting --ball-end: --csv, --teeth and --diameter-mm are required\n";
    return 2;
  }
  const identify::BallEndTest t{a.teeth, a.diameter_mm, a.helix_deg, a.order};
  identify::BallEndFit f;
  try {
    f = identify::identify_ball_end(identify::read_ball_end_csv(a.csv_path), t);
  } catch (const std::invalid_argument& e) {
    std::cerr << "robodamp identify cutting --ball-end: " << e.what() << '\n';
    return 2;
  }
  const identify::BallEndReport r = identify::ball_end_report(f, t, a.csv_path);
  if (!print_identified(a, r.text, r.json, r.yaml)) return 1;
  return 0;
}

}  // namespace robodamp::apps
