"""The thesis's cohesive test cases as data (thesis Tables 6.1, 6.2, 6.3).

Case A and Case B (Table 6.1): ρ = 400 kg/m³, θ = 30°; the tabulated c0 is the cohesion at zero
consolidation, converted with eq. 6.9 (the thesis says so: "The cohesion at zero consolidation
stress (c0) is reported in Table 6.1" next to eq. 6.9). Case A: a pharmaceutical powder; Case B:
a hypothetical clay-like material on frictionless walls.

Eckhoff & Leversen powders (Table 6.2): polymer and SiC. The table labels 519 Pa and 175 Pa
"Cohesion at zero consolidation stress, c0", but docs/theory/hopper_theory.md §0 item 3, §i shows that the thesis's
own Table 6.3 theory values cannot follow from that with eq. 6.9 (the polymer's McLean 35 cm
needs f_c ≈ 1410 Pa at the arch, below the eq. 6.9 value f_c0 = 1952 Pa). This is an OPEN
QUESTION, so both readings are provided, named:

  reading "c0"  : the tabulated value is c0; f_c0 = 2 c0 cos φ/(1 − sin φ) (eq. 6.9), as documented;
  reading "fc0" : the tabulated value is f_c0 itself (no eq. 6.9); the reading that fits the
                  polymer row (to ~2 % with other choices, docs/theory/hopper_theory.md §i.3), not the SiC row.

Elastic constants (E = 10 MPa, ν = 0.2) are the thesis's arbitrary choice (Table 6.2 footnote).
The fill heights of the experiments are unknown; EL_HEIGHT (1 m above the apex) is our default
and every table states it.
"""
from __future__ import annotations

from dataclasses import dataclass

from .model import Hopper, Material
from .mohr import fc_from_c

__all__ = ["Case", "CASES", "READINGS", "case", "TABLE_6_3", "EL_HEIGHT", "material_for"]

READINGS = ("c0", "fc0")
EL_HEIGHT = 1.0   #: m above the apex, assumed for the Eckhoff & Leversen hoppers (not reported)

#: thesis Table 6.3 theoretical values (cm); experiment and FEM columns are held back
TABLE_6_3 = {
    "polymer": {"mclean": 35.0, "jenike": 28.0, "enstad": 30.0},
    "sic": {"mclean": 12.0, "jenike": 10.2, "enstad": 10.4},
}


@dataclass(frozen=True)
class Case:
    """One tabulated case: the raw table values (c_tab is the tabulated "c0" in Pa)."""

    key: str
    name: str
    source: str
    theta_deg: float
    rho: float
    phi_deg: float
    phi_w_deg: float
    k: float
    c_tab: float
    height: float
    E: float = 10e6
    nu: float = 0.2
    readings: tuple = ("c0",)

    def fc0(self, reading: str = "c0") -> float:
        """f_c0 under a reading: "c0" → eq. 6.9 of the tabulated value; "fc0" → the value itself."""
        if reading not in self.readings:
            raise ValueError(f"case {self.key}: reading {reading!r} not offered (has {self.readings})")
        if reading == "c0":
            return fc_from_c(self.c_tab, self.phi_deg)
        return self.c_tab

    def material(self, reading: str = "c0") -> Material:
        return Material(rho=self.rho, phi_deg=self.phi_deg, phi_w_deg=self.phi_w_deg, k=self.k,
                        fc0=self.fc0(reading), E=self.E, nu=self.nu,
                        name=self.name + (f" (reading {reading})" if len(self.readings) > 1 else ""))

    def hopper(self, height: float | None = None, outlet_width: float | None = None) -> Hopper:
        return Hopper(theta_deg=self.theta_deg, height=self.height if height is None else height,
                      outlet_width=outlet_width)


CASES = {
    "A": Case("A", "Case A (pharmaceutical powder)", "thesis Table 6.1", theta_deg=30.0, rho=400.0,
              phi_deg=40.0, phi_w_deg=20.0, k=0.2, c_tab=350.0, height=2.0),
    "B": Case("B", "Case B (clay-like, frictionless walls)", "thesis Table 6.1", theta_deg=30.0,
              rho=400.0, phi_deg=20.0, phi_w_deg=0.0, k=0.0, c_tab=800.0, height=2.0),
    "polymer": Case("polymer", "Eckhoff & Leversen fine polymer powder", "thesis Table 6.2",
                    theta_deg=14.5, rho=440.0, phi_deg=34.0, phi_w_deg=26.0, k=0.62, c_tab=519.0,
                    height=EL_HEIGHT, readings=READINGS),
    "sic": Case("sic", "Eckhoff & Leversen fine SiC powder", "thesis Table 6.2", theta_deg=16.0,
                rho=900.0, phi_deg=28.6, phi_w_deg=33.3, k=0.47, c_tab=175.0, height=EL_HEIGHT,
                readings=READINGS),
}


def case(key: str) -> Case:
    lookup = {k.lower(): v for k, v in CASES.items()}
    try:
        return lookup[key.lower()]
    except KeyError:
        raise KeyError(f"unknown case {key!r}; one of {list(CASES)}") from None


def material_for(key: str, reading: str = "c0") -> Material:
    return case(key).material(reading)
