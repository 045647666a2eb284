"""State estimation: the Kalman filter and the robust filter (the RLQR's dual)."""

__all__: list[str] = []
