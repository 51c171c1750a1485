"""Exceptions users can catch. Every error prebo raises on bad input is a `PreboError`."""


class PreboError(Exception):
    """Base class of all prebo errors."""


class InputError(PreboError, ValueError):
    """An input file, particle, state or option that prebo cannot accept."""


class SpinError(InputError):
    """A total spin the identical particles of a group cannot form."""


class BasisFileError(PreboError):
    """A basis file that is missing, corrupt, truncated or inconsistent."""


class NotPositiveDefiniteError(PreboError):
    """An exponent matrix A (or the overlap matrix) is not positive definite."""


class IllConditionedError(NotPositiveDefiniteError):
    """An exponent matrix too ill-conditioned for accurate integrals."""


class LinearDependenceError(PreboError):
    """The overlap matrix is numerically singular beyond the chosen threshold."""


class CancellationError(PreboError):
    """A function whose elements double precision cannot give: nearly annihilated by the
    symmetriser, or with a CM kinetic energy that swamps its internal one."""


class ShapeError(PreboError):
    """Arrays whose shapes do not fit together (raised by the Rust core)."""


class UnsupportedError(PreboError):
    """A request prebo does not implement (e.g. a basis type for a state)."""


class SeparabilityError(PreboError):
    """A basis that does not factor into CM x internal parts where that is required."""


class OutputError(PreboError):
    """An output file or folder that cannot be written."""


class NonFiniteError(PreboError):
    """A matrix element or result that is not a finite number (NaN or infinite)."""


class StalledError(PreboError):
    """An optimisation that cannot proceed with its settings (every trial rejected)."""


class RanksDivergedError(PreboError):
    """MPI ranks that no longer make the same calls: their replicated state differs (nodes of
    different CPUs or BLAS; parallel.py)."""
