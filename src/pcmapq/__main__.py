from pcmapq.cli import main

main()
