#pragma once
// The two towers of the site service's tests (test_site_arbiter.cpp, test_schedule_bound.cpp).
#include "crane/anti_collision/site_layout.hpp"

namespace crane::anti_collision::test_sites {

// Two towers 2 m apart on the x axis, jibs 1.4 m long, 6 x 8 cm section, mast 8 cm, loads of
// radius 5 cm: A at (0, 0) with its jib at 2.5 m, B at (2, 0) at `b_height`, heading +x at slew 0.
inline SiteLayout two_towers(double b_height = 3.0) {
  SiteLayout s;
  s.name = "two";
  s.margins = {0.30, 0.15, 0.05};
  s.paths = {0.0, 0.0, 0.0, 0.0};  // no allowance unless a test sets one
  for (int i = 0; i < 2; ++i) {
    SiteCrane c;
    c.name = i == 0 ? "a" : "b";
    c.base = {2.0 * i, 0.0};
    c.jib_height = i == 0 ? 2.5 : b_height;
    c.jib_length = 1.4;
    c.counter_jib_length = 0.4;
    c.jib_width = 0.06;
    c.jib_depth = 0.08;
    c.mast_width = 0.08;
    c.trolley_min = 0.05;
    c.trolley_max = 1.3;
    c.slew_min = -3.0;
    c.slew_max = 3.0;
    c.hook_height_min = c.jib_height - 2.0;
    c.hook_height_max = c.jib_height - 0.2;
    c.load_radius = 0.05;
    c.domain_id = 11 + i;
    s.cranes.push_back(c);
  }
  return s;
}

}  // namespace crane::anti_collision::test_sites
