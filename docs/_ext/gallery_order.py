"""Order of the examples in the gallery (sphinx-gallery's ``within_subsection_order``)."""

ORDER = ("plot_truck_overload.py", "plot_hinf_input_bound.py", "plot_output_feedback_hinf.py",
         "plot_truck_robust_analysis.py",
         "plot_molsp_zdt1.py", "plot_experiment_statistics.py", "plot_applied_selection.py")


class ExampleOrder:
    """Sort key: the files of :data:`ORDER` first, in that order, then the others by name."""

    def __init__(self, src_dir: str):
        self.src_dir = src_dir

    def __call__(self, filename: str):
        return (ORDER.index(filename), "") if filename in ORDER else (len(ORDER), filename)

    def __repr__(self) -> str:          # sphinx-gallery caches on it
        return f"<{type(self).__name__}>"
