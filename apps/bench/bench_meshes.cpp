// Shared meshes for the benchmark apps (compiled into each *_bench executable); empty for now.
