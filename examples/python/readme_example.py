import caliber, numpy as np
bunny = caliber.Model.load("data/meshes/bunny00.off")        # or caliber.Model(caliber.Mesh(vertices, faces))
moved = caliber.Pose((0.002, 0.001, 0.0), (0.999, 0.02, 0.03, 0.01))  # translation, quaternion (w, x, y, z)
r = caliber.query(bunny, caliber.Pose(), bunny, moved, kind="proximity", tolerance=0.002)
print(len(r), r.pairs[:3], r.distances[:3], r.node_tests)    # numpy arrays: pairs k x 2, points_a/points_b/normals k x 3
engine = caliber.Engine()                                     # the parallel engine (stealing, the threads the process allows)
step = engine.step([bunny, bunny], [caliber.Pose(), moved], [(0, 1)], kind="proximity", tolerance=0.002)
path = np.tile([0.0, 0.001, 0.0, 0.999, 0.02, 0.03, 0.01], (1000, 1))  # 1000 poses, N x 7 (or N x 4 x 4 matrices)
path[:, 0] = np.linspace(-0.3, 0.3, 1000)                             # B slides along x
hits = caliber.query_many(bunny, caliber.Pose(), bunny, path, max_pairs=1)  # first hit at every pose, in parallel
print(hits.hit.sum(), "of", len(hits), "poses touch")                 # per pose: hit, distance; per pair: rows with their entry
