"""Heating of the SFB film by the slip: the liquid's heat capacity and the temperature rise.

The viscous energy of a slip heats the film volume A·D with the heat capacity
of bulk liquid OMCTS (Klein's note [29] makes the same assumption); no heat
leaves the film during the slip, so the rise is an upper bound.

OMCTS near 25 °C: ρ = 956 kg/m³ (supplier value; the Colonna et al. 2006
equation of state gives 941) and c_p = 1.49 kJ/(kg·K) (441 J/(mol·K), the
temperature derivative of the saturated-liquid enthalpy of the Colonna et al.,
Fluid Phase Equilib. 244, 193 (2006) equation of state as tabulated in
CoolProp's D4 file, at 298 K).

Example
-------
>>> round(temperature_rise(4e-13, 4e-10, 3.5e-9), 3)       # Klein's cycle, K
0.201
"""
from __future__ import annotations

from dataclasses import dataclass

__all__ = ["LiquidProperties", "OMCTS_LIQUID", "temperature_rise"]


@dataclass(frozen=True)
class LiquidProperties:
    """Bulk liquid properties used for the film's heat capacity (SI).

    Attributes
    ----------
    density : float
        kg/m³.
    heat_capacity : float
        Specific isobaric heat capacity, J/(kg·K).
    source : str
    """

    density: float
    heat_capacity: float
    source: str = ""

    @property
    def volumetric_heat_capacity(self) -> float:
        """ρ c_p, J/(m³·K)."""
        return self.density * self.heat_capacity


#: Bulk liquid OMCTS near 25 °C (see the module docstring for the sources).
OMCTS_LIQUID = LiquidProperties(
    density=956.0, heat_capacity=1490.0,
    source=("rho = 956 kg/m3 (25 C, supplier value; Colonna et al. 2006 EOS: 941); "
            "c_p = 1.49 kJ/(kg K) = 441 J/(mol K), d h_sat,liq/dT at 298 K from the "
            "Colonna et al. (Fluid Phase Equilib. 244, 193 (2006)) EOS, CoolProp D4"))


def temperature_rise(energy: float, area: float, thickness: float,
                     liquid: LiquidProperties = OMCTS_LIQUID) -> float:
    """Adiabatic temperature rise of the film volume A·D heated by ``energy`` (K)."""
    return energy / (liquid.volumetric_heat_capacity * area * thickness)
