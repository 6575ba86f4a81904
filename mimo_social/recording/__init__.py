"""Rerun recordings of simulations (``.rrd`` files on disk: no viewer, no network).

``recorder``: :class:`Recorder`, which writes an env's steps (the layout of a recording is in
its docstring); ``episodes``: one episode (:func:`record_episode`) or every k-th episode during
training (:class:`RecordingParallelEnv`, :func:`recording_env_fn`); ``summary``: what a file
holds (:func:`summarize`); ``streams``: Rerun file streams that free their threads when closed and
write errors that name the file and the cause (:class:`RecordingFileError`); ``torn``: the whole
part of a file cut off mid-write by a killed run (:func:`salvage`). The parts of a
recording: ``geometry`` (geom shapes), ``faces`` (expressions), ``eyes``, ``skin``, ``contacts``,
``blueprint`` (viewer layout), ``columns`` (Arrow columns and the row buffer).
"""

from .columns import SIM_TIME, STEP
from .contacts import CONTACTS_PATH
from .episodes import (
                       FIRST_VEC_WORKER,
                       RecordingParallelEnv,
                       RecordSubEnv,
                       record_episode,
                       recording_env_fn,
)
from .eyes import EYE_FORMATS
from .geometry import HIDDEN_GEOM_GROUP, geom_archetype, geom_rgba
from .recorder import Recorder, parallel_of
from .streams import RecordingFileError
from .skin import (
                   SKIN_FORCE_RANGE,
                   SKIN_LEGEND_PATH,
                   SKIN_LEGEND_TEXT_PATH,
                   SKIN_RADIUS_RANGE,
                   force_colors,
                   force_radii,
)
from .summary import format_summary, read_batches, summarize
from .torn import salvage, whole_length

__all__ = [
                       "CONTACTS_PATH",
                       "EYE_FORMATS",
                       "FIRST_VEC_WORKER",
                       "HIDDEN_GEOM_GROUP",
                       "SIM_TIME",
                       "SKIN_FORCE_RANGE",
                       "SKIN_LEGEND_PATH",
                       "SKIN_LEGEND_TEXT_PATH",
                       "SKIN_RADIUS_RANGE",
                       "STEP",
                       "RecordSubEnv",
                       "Recorder",
                       "RecordingFileError",
                       "RecordingParallelEnv",
                       "force_colors",
                       "force_radii",
                       "format_summary",
                       "geom_archetype",
                       "geom_rgba",
                       "parallel_of",
                       "read_batches",
                       "record_episode",
                       "recording_env_fn",
                       "salvage",
                       "summarize",
                       "whole_length",
]
