#pragma once
// The `overlap` method: the wave-algorithm paper's search for the rotation and translation that best overlap two
// grids (after Birk & Carpin 2006), made global and fast. Rotations come from Hough spectra
// (Carpin 2008), translations from an FFT correlation of the wall agreement on a coarse pyramid
// level; the common refine step then takes every candidate to sub-cell accuracy.
#include <vector>

#include "merging/hypothesis.h"
#include "merging/prepared_grid.h"

namespace fleetmap::merging {

struct OverlapSearchOptions {
  // The translation search runs on the finest level whose larger side is at most this. On 1000 x
  // 1000-cell windows of real 5 cm laser maps, searched on 63 x 63 cells of 0.8 m, the right
  // placement was below the eighth maximum at the right rotation; on 125 x 125 cells of 0.4 m it was
  // the first (bench/README.md, "Large real maps searched on finer cells").
  int search_cells = 128;
  // ... but never on cells larger than this (metres, from the grid's resolution): rooms and doors
  // must stay a few cells wide, however large the map.
  double max_search_cell_m = 0.8;
  int angle_bins = 360;        // spectrum resolution over [0, pi)
  int spectrum_peaks = 4;      // correlation peaks kept; each gives the rotations theta and theta + pi
  int translation_peaks = 8;   // correlation maxima kept per rotation (repeated places give several)
  int peak_separation = 3;     // cells of the search level between kept maxima
  double contradiction_weight = 3.0;  // walls on clear free space count against a translation this much
  // Besides the spectral candidates, rotations every `sweep_step_deg` (0: none). Costs time; the
  // method's second pass uses it when the spectral candidates find nothing reliable (maps without
  // dominant straight walls have flat spectra).
  double sweep_step_deg = 0.0;
  int max_hypotheses = 40;     // the best candidates by correlation score, over all rotations
};

// Candidate transforms, best first by the coarse correlation score.
std::vector<Hypothesis> overlap_hypotheses(const PreparedGrid& a, const PreparedGrid& b,
                                           const OverlapSearchOptions& options);

// The translation search alone, at the given rotations (radians, b into a).
std::vector<Hypothesis> overlap_hypotheses_at(const PreparedGrid& a, const PreparedGrid& b,
                                              const std::vector<double>& rotations,
                                              const OverlapSearchOptions& options);

// Rotation candidates (radians, b into a) from the Hough spectra of the full-resolution walls
// (coarse levels would add the horizontal and vertical steps of pooled slanted walls), best first.
std::vector<double> spectral_rotation_candidates(const PreparedGrid& a, const PreparedGrid& b,
                                                 const OverlapSearchOptions& options);

}  // namespace fleetmap::merging
