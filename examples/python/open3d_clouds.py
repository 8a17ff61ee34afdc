#!/usr/bin/env python3
"""Group clouds held as open3d.geometry.PointCloud: numpy in, places out.

    python3 examples/python/open3d_clouds.py data/office_3d/pcd data/office_3d/poses.txt

An Open3D pipeline keeps its clouds as PointCloud objects and their poses as 4x4 matrices; here
they come from the shipped PCD files and TUM poses, read by Open3D itself. Each cloud's points
cross into obsgroup as one numpy array.
"""

import argparse
from pathlib import Path

import numpy as np
import open3d as o3d

import obsgroup


def quaternion_pose(tx, ty, tz, qx, qy, qz, qw):
    pose = np.eye(4)
    pose[:3, :3] = o3d.geometry.get_rotation_matrix_from_quaternion([qw, qx, qy, qz])
    pose[:3, 3] = [tx, ty, tz]
    return pose


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="a folder of .pcd files (one cloud each, in the sensor frame)")
    parser.add_argument("poses", help="TUM poses: timestamp tx ty tz qx qy qz qw, one line per file")
    args = parser.parse_args()

    files = sorted(Path(args.folder).glob("*.pcd"))
    lines = [line.split() for line in Path(args.poses).read_text().splitlines() if line and line[0] != "#"]
    clouds = [o3d.io.read_point_cloud(str(f)) for f in files]
    poses = [quaternion_pose(*map(float, fields[1:8])) for fields in lines]

    grouping = obsgroup.Grouping()  # 3D clouds: the visibility model in its band of heights
    for cloud, pose in zip(clouds, poses):
        grouping.add(np.asarray(cloud.points), pose)
    partition = grouping.compute()

    for g, members in enumerate(partition.groups):
        merged = o3d.geometry.PointCloud()
        for i in members:
            merged += o3d.geometry.PointCloud(clouds[i]).transform(poses[i])
        merged = merged.voxel_down_sample(0.05)
        print(f"place {g}: clouds {members[0]}-{members[-1]} ({len(members)}), "
              f"{len(merged.points)} points after a 5 cm voxel filter")
    print(f"{len(clouds)} clouds, {len(partition)} places")


if __name__ == "__main__":
    main()
