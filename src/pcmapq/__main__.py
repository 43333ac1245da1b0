from pcmapq.cli import app

app()
