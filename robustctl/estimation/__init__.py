"""State estimation: the Kalman filter and the robust filter (the RLQR's dual).

* :func:`kalman`, :func:`kalman_gains` - the steady-state Kalman filter, one design or a batch;
* :func:`robust_kalman`, :func:`robust_kalman_gains` - the robust filter for norm-bounded
  uncertainty (Ishihara, Terra & Cerri 2015), one design or a batch;
* :class:`Estimator`, :class:`EstimatorBatch`, :class:`FilterRun` - their results.
"""

from .estimator import Estimator, EstimatorBatch, FilterRun
from .kalman import kalman, kalman_gains
from .robust_kalman import robust_kalman, robust_kalman_gains

__all__ = ["kalman", "kalman_gains", "robust_kalman", "robust_kalman_gains", "Estimator", "EstimatorBatch",
           "FilterRun"]
