"""The plantmech app: a local FastAPI server and a one-page front end (issue 14).

The server calls the same Python API as the CLI (``plantmech.workflows``,
``plantmech.optimize.jobs``) and returns arrays; the browser only draws them.
``scene`` turns the engine's results into drawing data (rigid placement of the pitch
curves, links and arms per frame), ``server`` holds the HTTP API, ``tasks`` the
background optimization and gear-cutting processes.
"""
