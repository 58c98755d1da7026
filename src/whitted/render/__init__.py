"""The render API shared by the CLI, the editor and the farm."""

from .api import CancelToken, JobState, Progress, RenderJob, RenderStats, render, render_aovs

__all__ = ["CancelToken", "JobState", "Progress", "RenderJob", "RenderStats", "render",
           "render_aovs"]
