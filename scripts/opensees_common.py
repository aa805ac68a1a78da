"""What the OpenSees cross-check scripts share: gravity through the bearing, the transient
analysis, and a step that falls back to substeps when Newton does not converge."""
import openseespy.opensees as ops


def settle_under_gravity(node, weight):
    """Applies the weight (N, down) at `node` in ten load steps and holds it; time is
    reset to 0 for the transient analysis that follows."""
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(node, 0.0, -weight, 0.0)
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", 1e-12, 50)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 0.1)
    ops.analysis("Static")
    assert ops.analyze(10) == 0
    ops.loadConst("-time", 0.0)


def start_transient(tol, integrator, beta_k=0.0):
    """A transient analysis: Newton with NormDispIncr `tol` (m), the `integrator`
    arguments (e.g. ("Newmark", 0.5, 0.25)), stiffness-proportional Rayleigh damping
    `beta_k` if positive."""
    ops.wipeAnalysis()
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("FullGeneral")
    ops.test("NormDispIncr", tol, 100)
    ops.algorithm("Newton")
    ops.integrator(*integrator)
    if beta_k > 0:
        ops.rayleigh(0.0, beta_k, 0.0, 0.0)
    ops.analysis("Transient")


def step(dt):
    """One step of `dt`; when Newton fails, ten substeps, each falling back to modified
    Newton on the initial tangent. Returns True when the step needed the substeps."""
    if ops.analyze(1, dt) == 0:
        return False
    sub = 10
    for _ in range(sub):
        ok = ops.analyze(1, dt / sub)
        if ok != 0:
            ops.algorithm("ModifiedNewton", "-initial")
            ok = ops.analyze(1, dt / sub)
            ops.algorithm("Newton")
        if ok != 0:
            raise SystemExit(f"OpenSees failed at t = {ops.getTime()}")
    return True
