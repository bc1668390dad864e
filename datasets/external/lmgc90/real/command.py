"""LMGC90 run of the sample of gen_sample.py (pylmgc90.chipy, contact dynamics, NLGS): the disks
fall and settle for NSTEPS steps of DT; every FREQ steps LMGC90 writes OUTBOX/DOF.OUT.k and
OUTBOX/Vloc_Rloc.OUT.k, and this script writes lmgc90_reference_k.csv: LMGC90's own numbers for
every body at that step, read from the solver with full precision: its coordinates `Coor_`
(x, y, theta) and its contact reaction `Reac_` (LMGC90 keeps the impulse `Ireac` of the step and
returns `Reac_` = `Ireac`/H: the resultant force and moment of its contacts, N and N m per metre).

    python command.py
"""

from pylmgc90 import chipy

DT = 1.0e-3
NSTEPS = 400
FREQ = 200

chipy.Initialize()
chipy.checkDirectories()
chipy.utilities_DisableLogMes()
chipy.SetDimension(2, 1)
chipy.TimeEvolution_SetTimeStep(DT)
chipy.Integrator_InitTheta(0.5)
chipy.ReadDatbox(deformable=False)
chipy.ComputeMass()

k = 0
for step in range(1, NSTEPS + 1):
    chipy.IncrementStep()
    chipy.ComputeFext()
    chipy.ComputeBulk()
    chipy.ComputeFreeVelocity()
    chipy.SelectProxTactors()
    chipy.RecupRloc()
    chipy.ExSolver("Stored_Delassus_Loops         ", "Quad ", 1.0e-6, 1.0, 1000, 50)
    chipy.UpdateTactBehav()
    chipy.StockRloc()
    chipy.ComputeDof()
    chipy.UpdateStep()
    chipy.WriteOut(FREQ)
    if step % FREQ == 0:
        k += 1
        with open(f"lmgc90_reference_{k}.csv", "w") as f:
            f.write(f"# LMGC90 step {step}, time {chipy.TimeEvolution_GetTime()!r} s, dt {DT!r} s\n")
            f.write("body,x_m,y_m,theta_rad,reac_x_N,reac_y_N,reac_moment_Nm\n")
            for b in range(1, chipy.RBDY2_GetNbRBDY2() + 1):
                c = chipy.RBDY2_GetBodyVector("Coor_", b)
                r = chipy.RBDY2_GetBodyVector("Reac_", b)
                f.write(",".join([str(b)] + [repr(float(v)) for v in (*c[:3], *r[:3])]) + "\n")

chipy.Finalize()
