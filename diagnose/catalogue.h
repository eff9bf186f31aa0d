#ifndef KINCAL_DIAGNOSE_CATALOGUE_H_
#define KINCAL_DIAGNOSE_CATALOGUE_H_

// The catalogue of causes `diagnose model` tests, apart from the selection
// procedure (diagnose/model_diagnosis.cc). Each cause family owns a slice of
// the chain's parameter blocks and a hook in the chain (calib/chain.h, the
// family table); here it gets its candidates (where it applies on the data),
// its parameters and its magnitude in the spec's units. A new cause: its
// block entries and hook in calib/chain.h, its names in calib/model_state.cc,
// and one entry in each function below.
//
// Causes (docs/DIAGNOSE.md has the equations and units):
//   backlash, compliance, cyclic (cyclic2, cyclic3), gain, axis_tilt, drift
//   (the spec's catalogue); elastostatic (joint deflection under the
//   gravity torque of the link masses), thermal (growth of a row's lengths
//   with temp_c or time), mount_compliance (base tilt under the arm's
//   gravity moment), gravity (mount_compliance and the elastostatic
//   deflection of every joint together, one candidate), transmission (a joint error that varies along the
//   joint's travel: on revolute joints a regularised periodic function of
//   the angle over the whole revolution, diagnose/periodic_basis.h; on
//   prismatic joints a sine series over the travel of the data).

#include <string>
#include <vector>

#include "calib/chain.h"
#include "calib/fit.h"
#include "calib/model_state.h"
#include "diagnose/periodic_basis.h"

namespace kincal {

// Every cause name the catalogue knows (the --causes vocabulary).
const std::vector<std::string>& CatalogueCauses();

// Cyclic candidates carry their harmonic in the cause name: "cyclic" (first,
// the spec's cause), "cyclic2", "cyclic3". CyclicHarmonic returns 1..3 for
// them and 0 for any other cause.
int CyclicHarmonic(const std::string& cause);
std::string CyclicCause(int harmonic);

// Transmission candidates carry their number of functions: "transmission8",
// "transmission16", "transmission24" (nested: each series contains the
// shorter ones; a periodic basis may support fewer, "transmissionN").
// TransmissionTerms returns N (1..24) for them, else 0.
int TransmissionTerms(const std::string& cause);
std::string TransmissionCause(int terms);
// The spec's name of an internal cause: "cyclic" for cyclic2/3,
// "transmission" for transmissionN, else the cause itself.
std::string SpecCauseName(const std::string& cause);

// Sets the travel of every moving joint whose chain row has none
// (ChainRow::transmission_lo/hi) to the range of its readings in
// `measurements`: the interval the transmission family's series lives on.
// Revolute joints also get their periodic basis from the readings
// (diagnose/periodic_basis.h): their transmission is a function of the angle
// over the whole revolution; prismatic joints keep the sine series.
void SetTransmissionTravel(const std::vector<Measurement>& measurements,
                           Chain* chain,
                           const PeriodicBasisOptions& periodic = {});

// The transmission candidates' numbers of functions on a row: 8, 16, 24 for
// the sine series over a travel; for a periodic basis those of them that
// the readings support, and the number supported when it is not one of
// them (none below 2).
std::vector<int> TransmissionTermChoices(const ChainRow& row);

// One catalogue candidate: a cause on a joint (joint -1 for drift,
// mount_compliance and gravity).
struct Candidate {
  std::string cause;
  int joint = -1;
  std::vector<ParamInfo> params;
  std::string Label(const Chain& chain) const;  // "backlash:j3", "drift"
};

Candidate MakeCandidate(const Chain& chain, const std::string& cause,
                        int joint);

// All catalogue candidates that apply to this chain and data (before the
// identifiability check). `measurements` give s, tau, tau_mass, moment, t
// and the thermal input.
std::vector<Candidate> CatalogueCandidates(
    const Chain& chain, const std::vector<Measurement>& measurements,
    const std::vector<std::string>& causes = {});

// The scale that turns a candidate's parameter into its magnitude: the
// largest |torque| (compliance, elastostatic), the largest horizontal
// gravity moment (mount_compliance), the nominal row length (thermal); 1
// otherwise.
double MagnitudeScale(const std::string& cause, int joint, const Chain& chain,
                      const std::vector<Measurement>& ms);

// A candidate's magnitude in the spec's units with its 95 % interval, from a
// fitted state and its FitSummary covariance (NaN interval when absent).
struct Magnitude {
  double value = 0.0;
  double sigma = 0.0;
  double ci_low = 0.0, ci_high = 0.0;
  std::string unit;
};
// `scale` from MagnitudeScale (historically the largest |tau|).
Magnitude CandidateMagnitude(const Candidate& c, const ModelState& state,
                             const FitSummary& fit, double scale);

}  // namespace kincal

#endif  // KINCAL_DIAGNOSE_CATALOGUE_H_
