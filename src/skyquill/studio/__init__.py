"""The drawing studio: draw in a browser, plan, preview the flight, download (paper 000 Fig. 2).

The only package that imports the web framework. :func:`create_app` builds the
FastAPI app; ``skyquill studio`` serves it with uvicorn on 127.0.0.1.
"""

from skyquill.studio.app import create_app
from skyquill.studio.jobs import JobManager

__all__ = ["JobManager", "create_app"]
