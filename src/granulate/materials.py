"""Materials: density, elastic constants, fracture energy, horizon and force model.

All values in SI units. Give exactly two of ``bulk_modulus`` (K), ``shear_modulus`` (G),
``youngs_modulus`` (E) and ``poisson_ratio`` (nu); the other two are derived
(K = E / (3 (1 - 2 nu)), G = E / (2 (1 + nu))). Give the horizon either absolute (``horizon``,
metres) or relative to the mesh size of each body (``horizon_factor``, default 3).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from granulate import _core
from granulate.errors import InputError
from granulate.input_errors import NOT_BOOL, api_error

ForceModelName = Literal["lps", "pmb"]
_Number = Annotated[float | None, NOT_BOOL]  # a number or None, never a yes/no
MOST_MODULUS = 1e14  # Pa: 200 times diamond's bulk modulus
InfluenceName = Literal["constant", "linear", "gaussian", "inverse"]


class _CalledFromPython(type(BaseModel)):  # type: ignore[misc]
    """Material(...) called in Python raises InputError, told as a case file's problems are;
    inside a case file's validation the model stays a pydantic model (its errors get key
    paths there)."""

    def __call__(cls, *args: Any, **data: Any) -> Any:
        try:
            return super().__call__(*args, **data)
        except ValidationError as error:
            raise api_error(cls.__name__, error, data, cls) from None


class Material(BaseModel, metaclass=_CalledFromPython):
    """A peridynamic material.

    Attributes:
        density: mass density rho [kg/m^3].
        bulk_modulus, shear_modulus, youngs_modulus, poisson_ratio: two of them [Pa, Pa, Pa, -].
        fracture_energy: critical energy release rate Gc [J/m^2]; the critical bond stretch s0
            follows from it (see ``critical_stretch``). Required when ``fracture`` is true.
        horizon: absolute horizon delta [m]; or ``horizon_factor`` times the body's mesh size.
        model: ``"lps"`` (linear peridynamic solid, state-based; default) or ``"pmb"``
            (bond-based; its Poisson ratio is fixed at 1/4, 1/3 in plane stress).
        influence: influence function J(r/delta): ``constant`` 1, ``linear`` 1 - r/delta,
            ``gaussian`` exp(-(r/delta)^2/0.16), ``inverse`` delta/r.
        fracture: false for an elastic material whose bonds never break.
        break_in_compression: bonds also break when the stretch falls below -s0.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    def __repr_args__(self) -> Any:
        """The constants given (not the ones left out), for a readable repr."""
        defaults = type(self).model_fields
        for name, value in super().__repr_args__():
            if value is not None and (name is None or value != defaults[name].default):
                yield name, value

    density: Annotated[float, NOT_BOOL] = Field(gt=0, allow_inf_nan=False, description="[kg/m^3]")
    bulk_modulus: _Number = Field(default=None, gt=0, allow_inf_nan=False, description="K [Pa]")
    shear_modulus: _Number = Field(default=None, gt=0, allow_inf_nan=False, description="G [Pa]")
    youngs_modulus: _Number = Field(default=None, gt=0, allow_inf_nan=False, description="E [Pa]")
    poisson_ratio: _Number = Field(
        default=None, gt=-1, lt=0.5, allow_inf_nan=False, description="nu [-]"
    )
    fracture_energy: _Number = Field(
        default=None, gt=0, allow_inf_nan=False, description="Gc [J/m^2]"
    )
    horizon: _Number = Field(default=None, gt=0, allow_inf_nan=False, description="delta [m]")
    horizon_factor: _Number = Field(
        default=None, ge=1, allow_inf_nan=False, description="delta / mesh size [-] (default 3)"
    )
    model: ForceModelName = Field("lps", description="lps (state-based) or pmb (bond-based)")
    influence: InfluenceName = Field("linear", description="J(r / delta)")
    fracture: bool = Field(True, description="false: bonds never break")
    break_in_compression: bool = Field(False, description="bonds also break below -s0")

    @model_validator(mode="after")
    def _check(self) -> Material:
        given = [
            name
            for name in ("bulk_modulus", "shear_modulus", "youngs_modulus", "poisson_ratio")
            if getattr(self, name) is not None
        ]
        if len(given) != 2:
            raise ValueError(
                "give exactly two elastic constants out of bulk_modulus, shear_modulus, "
                f"youngs_modulus, poisson_ratio (got {', '.join(given) or 'none'})"
            )
        if self.fracture and self.fracture_energy is None:
            raise ValueError("fracture_energy (Gc, J/m^2) is required; or set fracture=False")
        if self.horizon is not None and self.horizon_factor is not None:
            raise ValueError(
                "give horizon (absolute) or horizon_factor (times mesh size), not both"
            )
        moduli = self.elastic_moduli()  # raises for E outside what K or G allow
        if not max(moduli) <= MOST_MODULUS:
            raise ValueError(
                f"the elastic constants give moduli (K, G) = ({moduli[0]:.3g}, {moduli[1]:.3g}) "
                f"Pa, beyond any solid (diamond: K about 4.4e11 Pa; at most {MOST_MODULUS:.0e}); "
                "give them in Pa"
            )
        return self

    def elastic_moduli(self) -> tuple[float, float]:
        """(K, G) in Pa from whichever two constants were given."""
        K, G, E, nu = self.bulk_modulus, self.shear_modulus, self.youngs_modulus, self.poisson_ratio
        if K is not None and G is not None:
            return K, G
        if E is not None and nu is not None:
            return E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
        if K is not None and E is not None:
            if E >= 9 * K:
                raise ValueError("youngs_modulus must be below 9 bulk_modulus")
            return K, 3 * K * E / (9 * K - E)
        if G is not None and E is not None:
            if E >= 3 * G:
                raise ValueError("youngs_modulus must be below 3 shear_modulus (nu < 0.5)")
            return G * E / (3 * (3 * G - E)), G
        if K is not None and nu is not None:
            return K, 3 * K * (1 - 2 * nu) / (2 * (1 + nu))
        assert G is not None and nu is not None
        return 2 * G * (1 + nu) / (3 * (1 - 2 * nu)), G

    def resolved_horizon(self, mesh_size: float) -> float:
        """Horizon delta [m] for a body of mesh size h: ``horizon`` or ``horizon_factor * h``."""
        if self.horizon is not None:
            return self.horizon
        return (self.horizon_factor or 3.0) * mesh_size

    def core_params(self, mesh_size: float) -> _core.MaterialParams:
        """The C++ parameter struct for a body of mesh size h."""
        K, G = self.elastic_moduli()
        params = _core.MaterialParams()
        params.model = getattr(_core.ForceModel, self.model)
        params.density = self.density
        params.bulk_modulus = K
        params.shear_modulus = G
        params.horizon = self.resolved_horizon(mesh_size)
        params.fracture_energy = self.fracture_energy or 0.0
        params.influence = getattr(_core.InfluenceKind, self.influence)
        params.fracture = self.fracture
        params.break_in_compression = self.break_in_compression
        return params

    def critical_stretch(self, mesh_size: float, dimension: int, plane: str = "strain") -> float:
        """Critical bond stretch s0 for this material in a body of mesh size h.

        From the energy balance: rigidly separating two half-spaces dissipates Gc per unit
        area (``_core.fracture_coefficients`` gives the dimensionless integrals).
        """
        try:
            derived = _core.Material.make(
                self.core_params(mesh_size), dimension, getattr(_core.PlaneMode, plane)
            )
        except ValueError as error:
            raise InputError(str(error)) from None
        return derived.critical_stretch
