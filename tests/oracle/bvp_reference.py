"""Reference runs of scipy.integrate.solve_bvp for designer/tests/bvp.rs.

Run: python3 tests/oracle/bvp_reference.py
Prints, per problem, the final node count, max RMS residual and key numbers,
to compare with the Rust solver (same algorithm, so counts should agree).
"""
import numpy as np
from scipy.integrate import solve_bvp


def layer(eps=1e-3):
    f = lambda t, y: np.vstack((y[1], y[1] / eps))
    jac = lambda t, y: np.broadcast_to(np.array([[0, 1], [0, 1 / eps]])[:, :, None], (2, 2, t.size))
    bc = lambda ya, yb: np.array([ya[0], yb[0] - 1])
    t = np.linspace(0, 1, 11)
    y = np.vstack((t, np.ones_like(t)))
    s = solve_bvp(f, bc, t, y, fun_jac=jac, tol=1e-4, max_nodes=5000)
    n_in = np.sum(s.x >= 1 - 10 * eps)
    print(f"layer: status {s.status} nodes {s.x.size} in layer {n_in} niter {s.niter} max rms {s.rms_residuals.max():.3e}")


def bratu():
    f = lambda t, y: np.vstack((y[1], -np.exp(y[0])))
    bc = lambda ya, yb: np.array([ya[0], yb[0]])
    t = np.linspace(0, 1, 5)
    for g in (0.0, 3.0):
        y = np.zeros((2, 5)); y[0] = g
        s = solve_bvp(f, bc, t, y, tol=1e-6)
        print(f"bratu guess {g}: status {s.status} nodes {s.x.size} y'(0) = {s.y[1, 0]:.8f}")


def saturated(U=4.5):
    u = lambda p2: np.clip(-p2 / 2, -U, U)
    f = lambda t, y: np.vstack((y[1], u(y[3]), 0 * y[2], -y[2]))
    bc = lambda ya, yb: np.array([ya[0], ya[1], yb[0] - 1, yb[1]])
    t = np.linspace(0, 1, 11)
    s = solve_bvp(f, bc, t, np.zeros((4, 11)), tol=1e-6)
    tt = np.linspace(0, 0.5, 200001)
    uu = u(s.sol(tt)[3])
    tau1 = tt[np.argmax(uu < U - 1e-12)]
    print(f"saturated U={U}: status {s.status} nodes {s.x.size} p1 {s.y[2, 0]:.8f} tau1 ~ {tau1:.6f} "
          f"(analytic {0.5 - np.sqrt(0.75 - 3 / U):.6f})")


layer()
bratu()
saturated()
