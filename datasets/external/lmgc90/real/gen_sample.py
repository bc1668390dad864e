"""LMGC90 pre-processing of the sample of datasets/external/lmgc90/real (pylmgc90.pre): 36 rigid
disks (radii 4-6 mm, density 2500 kg/m3, seeded) on a 6 x 6 grid of 14 mm pitch, dropped into a
box of three JONCx walls (floor 100 mm wide, side walls 150 mm high), gravity (0, -9.81) m/s2,
IQS_CLB contacts (Coulomb friction 0.3) between disks (DKDKx) and with the walls (DKJCx).

    python gen_sample.py   # writes DATBOX/
"""

import math
import os

import numpy as np
from pylmgc90 import pre

dim = 2
rng = np.random.default_rng(15)

bodies = pre.avatars()
mats = pre.materials()
mods = pre.models()
svs = pre.see_tables()
tacts = pre.tact_behavs()

tdur = pre.material(name="TDURx", materialType="RIGID", density=2500.0)
pdur = pre.material(name="PDURx", materialType="RIGID", density=2500.0)
mats.addMaterial(tdur, pdur)
mod = pre.model(name="rigid", physics="MECAx", element="Rxx2D", dimension=dim)
mods.addModel(mod)

# walls: the floor at y = 0 (its surface), side walls at x = 0 and x = 0.1 m (inner surfaces)
t = 0.002  # half-thickness of the walls
floor = pre.rigidJonc(axe1=0.05 + 2 * t, axe2=t, center=[0.05, -t], model=mod, material=tdur, color="WALLx")
left = pre.rigidJonc(axe1=0.075, axe2=t, center=[-t, 0.075], model=mod, material=tdur, color="WALLx")
right = pre.rigidJonc(axe1=0.075, axe2=t, center=[0.1 + t, 0.075], model=mod, material=tdur, color="WALLx")
left.rotate(psi=math.pi / 2.0, center=left.nodes[1].coor)
right.rotate(psi=math.pi / 2.0, center=right.nodes[1].coor)
for w in (floor, left, right):
    w.imposeDrivenDof(component=[1, 2, 3], dofty="vlocy")
    bodies += w

pitch = 0.014
for j in range(6):
    for i in range(6):
        r = float(rng.uniform(0.004, 0.006))
        x = 0.0125 + i * 0.015 + (0.003 if j % 2 else 0.0)
        y = 0.007 + j * pitch
        bodies += pre.rigidDisk(r=r, center=[x, y], model=mod, material=pdur, color="GRAIN")

law = pre.tact_behav(name="iqsc0", law="IQS_CLB", fric=0.3)
tacts += law
svs += pre.see_table(CorpsCandidat="RBDY2", candidat="DISKx", colorCandidat="GRAIN",
                     CorpsAntagoniste="RBDY2", antagoniste="DISKx", colorAntagoniste="GRAIN",
                     behav=law, alert=0.001)
svs += pre.see_table(CorpsCandidat="RBDY2", candidat="DISKx", colorCandidat="GRAIN",
                     CorpsAntagoniste="RBDY2", antagoniste="JONCx", colorAntagoniste="WALLx",
                     behav=law, alert=0.001)

os.makedirs("DATBOX", exist_ok=True)
pre.writeDatbox(dim, mats, mods, bodies, tacts, svs, gravy=[0.0, -9.81, 0.0])
