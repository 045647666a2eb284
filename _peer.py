import numpy as np, control, warnings
def peer_level(F, G, Bw, Cz, Dzu, Dzw, gamma):
    """Feasibility of one level by python-control's dare (slycot SG02AD) on the game Riccati equation."""
    n, m = G.shape
    q = Bw.shape[1]
    B = np.hstack([G, Bw]); D = np.hstack([Dzu, Dzw])
    R = D.T @ D - np.diag(np.r_[np.zeros(m), gamma**2 * np.ones(q)])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            X, L, Kg = control.dare(F, B, Cz.T @ Cz, R, Cz.T @ D)
    except Exception:
        return None
    if not np.all(np.isfinite(X)) or np.max(np.abs(L)) >= 1.0:
        return None
    if np.linalg.eigvalsh(X).min() < -1e-8 * max(1.0, np.abs(X).max()):
        return None
    Hww = Bw.T @ X @ Bw + Dzw.T @ Dzw - gamma**2 * np.eye(q)
    if np.linalg.eigvalsh(Hww).max() >= 0:
        return None
    return -Kg[:m]
def peer_hinf(plant, Bw, Cz, Dzu, Dzw=None, rtol=1e-8):
    F, G = plant.F, plant.G
    Dzw = np.zeros((Cz.shape[0], Bw.shape[1])) if Dzw is None else Dzw
    lo = np.linalg.norm(Dzw, 2); hi = max(1.0, 2 * lo); its = 0
    while (K := peer_level(F, G, Bw, Cz, Dzu, Dzw, hi)) is None:
        lo, hi = hi, 2 * hi; its += 1
    while hi - lo > rtol * hi:
        mid = np.sqrt(lo * hi) if lo > 0 else hi / 2; its += 1
        Km = peer_level(F, G, Bw, Cz, Dzu, Dzw, mid)
        if Km is None: lo = mid
        else: hi, K = mid, Km
    return hi, K, its
