"""Post-processing of campaign results: impact ellipses, result files, summaries and plots."""

from ..ellipse import Ellipse as Ellipse
from ..ellipse import chi2_scale as chi2_scale
from ..ellipse import confidence_ellipse as confidence_ellipse
from .plots import plot_impacts as plot_impacts
from .results import SUMMARY_LEVELS as SUMMARY_LEVELS
from .results import Run as Run
from .results import format_summary as format_summary
from .results import load_inputs as load_inputs
from .results import load_outputs as load_outputs
from .results import load_run as load_run
from .results import load_trajectories as load_trajectories
from .results import report as report
from .results import summarize as summarize
