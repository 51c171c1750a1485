"""The results of a basis's levels, the pipeline's last stage (system → basis → integrals → eigen
→ level): `evaluate.evaluate`, the energies of the lowest levels with their uncertainties, virial
coefficients and bound or not; `expectation`, the registered operators and their values per class
of equivalent pairs or particles; `properties`, one level's properties and the levels' distance
distributions; `relativistic`, the Breit–Pauli terms of a level; `drachmann`, the regularised δ and
p⁴; `transitions` and `response`, lines and polarisabilities with a second basis; `bethe`, the
Bethe logarithm ln k₀. Each is a level's: the eigenvector of a root of the basis's matrices
(prebo.system.thresholds, the dissociation threshold that says whether a level is bound, is the
system's and the optimiser's too).
"""
