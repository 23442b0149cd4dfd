#pragma once
// The facts every stage of the stack shares, read once from the configuration (the `stack:`, `crane:` and
// `site:` blocks, crane::config::read_facts) and handed to each stage's constructor: the one
// place for the sample period, the drive voltage limit and the crane itself (its cable range
// included). A stage's own block never repeats them.

#include "crane/common/crane_parameters.hpp"
#include "crane/common/site.hpp"

namespace crane::common {

struct StackFacts {
  double sample_period{0.01};          // [s] T of the 100 Hz cycle, in [1e-4, 0.1]
  double voltage_limit{10.0};          // [V] magnitude limit of every drive command (tracking, friction
                                       // compensation, the supervisor, the actuation gate), in [0.1, 100]
  double lockstep_hang_timeout{5.0};   // [s] lockstep: wall time a cycle may wait before the chain is
                                       // reported hung (nothing is guessed: the cycle keeps waiting)
  CraneParameters crane;               // the crane as configured (cable range included)
  CraneKind crane_kind{CraneKind::tower};  // crane.kind: which crane, hence which axes the topics carry
  BridgeParameters bridge;             // crane.bridge: the overhead crane's bridge (crane_kind overhead only)
  Site site;                           // the jib height and the no-go zones (`site:`, optional: none)
};

}  // namespace crane::common
