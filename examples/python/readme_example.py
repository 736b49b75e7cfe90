import caliber, numpy as np
bunny = caliber.Model.load("data/meshes/bunny00.off")        # or caliber.Model(caliber.Mesh(vertices, faces))
moved = caliber.Pose((0.002, 0.001, 0.0), (0.999, 0.02, 0.03, 0.01))  # translation, quaternion (w, x, y, z)
r = caliber.query(bunny, caliber.Pose(), bunny, moved, kind="proximity", tolerance=0.002)
print(len(r), r.pairs[:3], r.distances[:3], r.node_tests)    # numpy arrays: pairs k x 2, points_a/points_b/normals k x 3
engine = caliber.Engine()                                     # the parallel engine (stealing, the threads the process allows)
step = engine.step([bunny, bunny], [caliber.Pose(), moved], [(0, 1)], kind="proximity", tolerance=0.002)
