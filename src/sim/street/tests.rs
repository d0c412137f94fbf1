use super::*;

#[test]
fn default_config_is_valid_and_toml_like_round_trip() {
    let c = StreetConfig::default();
    c.validate().unwrap();
    let json = serde_json::to_string(&c).unwrap();
    let back: StreetConfig = serde_json::from_str(&json).unwrap();
    assert_eq!(back, c);
    let partial: StreetConfig = serde_json::from_str(r#"{"speed": 8.0}"#).unwrap();
    assert_eq!(partial.speed, 8.0);
    assert_eq!(partial.lidar, LidarConfig::default());
    assert!(serde_json::from_str::<StreetConfig>(r#"{"sped": 8.0}"#).is_err());
}

fn distance_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

#[test]
fn walls_stay_clear_of_the_ego_path_and_face_the_street() {
    // 15 s: the first two turns of the default route.
    let sim = StreetSimulator::new(&StreetConfig::default(), 150, 4).unwrap();
    let street = sim.street();
    assert_eq!(street.segments.len(), 4);
    assert!(street.walls.len() > 20, "{}", street.walls.len());
    for w in &street.walls {
        let v = w.vertices();
        for k in 0..sim.frames() {
            let e = sim.ego(k);
            let d = distance_to_segment([e.x, e.y], [v[0][0], v[0][1]], [v[1][0], v[1][1]]);
            assert!(d > 6.0, "wall {} is {d} m from the ego at frame {k}", w.id);
        }
        assert!(w.length >= 5.0 && (6.0..=15.0).contains(&w.height), "{w:?}");
        // The normal points to the centreline of the wall's own segment.
        let mid = [0.5 * (v[0][0] + v[1][0]), 0.5 * (v[0][1] + v[1][1])];
        let seg = street.segments.iter().find(|s| s.dir == w.along).unwrap();
        let s = (mid[0] - seg.point[0]) * seg.dir[0] + (mid[1] - seg.point[1]) * seg.dir[1];
        let c = seg.at(s, 0.0);
        let side = w.normal[0] * c[0] + w.normal[1] * c[1] + w.offset();
        assert!((side - 12.0).abs() < 1e-6, "wall {}: {side}", w.id);
    }
}

#[test]
fn objects_keep_clear_of_the_ego_and_move_as_configured() {
    let config = StreetConfig::default();
    let sim = StreetSimulator::new(&config, 100, 8).unwrap();
    let street = sim.street();
    let t = &config.traffic;
    assert_eq!(
        street.objects.len(),
        t.parked_cars + t.moving_cars + t.pedestrians
    );
    let truth = sim.truth();
    for o in &truth.objects {
        assert!(!o.states.is_empty() || !o.kind.is_parked());
        for s in &o.states {
            let e = sim.ego(s.frame);
            let gap = (s.position[0] - e.x).hypot(s.position[1] - e.y);
            assert!(gap > 4.0, "object {} {gap} m from the ego", o.id);
            let v = s.velocity[0].hypot(s.velocity[1]);
            let ok = match o.kind {
                ObjectKind::ParkedCar | ObjectKind::ParkedVan => v == 0.0,
                ObjectKind::Car | ObjectKind::Van | ObjectKind::Truck => (5.0..=12.0).contains(&v),
                ObjectKind::Cyclist => (3.0..=7.0).contains(&v),
                ObjectKind::Pedestrian => (1.2..=1.4).contains(&v),
            };
            assert!(ok, "{o:?}");
            // The heading is along the velocity.
            if v > 0.0 {
                let heading = s.velocity[1].atan2(s.velocity[0]);
                assert!(crate::geometry::wrap_angle(heading - s.yaw).abs() < 1e-9);
            }
        }
        // Consecutive states move by velocity × frame period.
        for w in o.states.windows(2) {
            if w[1].frame == w[0].frame + 1 {
                for i in 0..2 {
                    let step = w[1].position[i] - w[0].position[i];
                    assert!((step - 0.1 * w[0].velocity[i]).abs() < 1e-9);
                }
            }
        }
    }
}

#[test]
fn oxts_packets_agree_with_the_positions_they_encode() {
    let sim = StreetSimulator::new(&StreetConfig::default(), 60, 2).unwrap();
    let packets: Vec<_> = (0..60).map(|k| sim.packet(k)).collect();
    let merc = Mercator::from_reference_latitude(packets[0].lat).unwrap();
    let xy: Vec<(f64, f64)> = packets.iter().map(|p| merc.project(p.lat, p.lon)).collect();
    for k in 1..59 {
        // Central differences of the encoded positions against the velocities.
        let ve = (xy[k + 1].0 - xy[k - 1].0) / 0.2;
        let vn = (xy[k + 1].1 - xy[k - 1].1) / 0.2;
        let p = &packets[k];
        assert!(
            (ve - p.ve).abs() < 0.05 && (vn - p.vn).abs() < 0.05,
            "frame {k}"
        );
        assert!((p.vf - p.ve.hypot(p.vn)).abs() < 1e-9);
        assert!((p.al - p.vf * p.wu).abs() < 1e-12 && p.wz == p.wu);
        let e = sim.ego(k);
        assert!(((xy[k].0 - xy[0].0) - e.x).abs() < 1e-6);
        assert!(((xy[k].1 - xy[0].1) - e.y).abs() < 1e-6);
    }
    assert!(packets.iter().any(|p| p.wu.abs() > 0.2), "no turn in 6 s");
}

#[test]
fn the_urban_street_holds_every_road_user_kind_and_clutter_off_their_rows() {
    let config = StreetConfig::urban();
    config.validate().unwrap();
    let sim = StreetSimulator::new(&config, 60, 3).unwrap();
    let street = sim.street();
    let t = &config.traffic;
    let count = |k: ObjectKind| street.objects.iter().filter(|o| o.kind == k).count();
    for (kind, n) in [
        (ObjectKind::ParkedCar, t.parked_cars),
        (ObjectKind::Car, t.moving_cars),
        (ObjectKind::Pedestrian, t.pedestrians),
        (ObjectKind::ParkedVan, t.parked_vans),
        (ObjectKind::Van, t.moving_vans),
        (ObjectKind::Truck, t.trucks),
        (ObjectKind::Cyclist, t.cyclists),
    ] {
        assert_eq!(count(kind), n, "{kind:?}");
    }
    let c = &config.clutter;
    let pieces = |k: ClutterKind| street.clutter.iter().filter(|p| p.kind == k).count();
    assert_eq!(
        [
            pieces(ClutterKind::Pole),
            pieces(ClutterKind::Trunk),
            pieces(ClutterKind::Hedge),
            pieces(ClutterKind::LowWall)
        ],
        [c.poles, c.trunks, c.hedges, c.low_walls]
    );
    // Every piece stands on the sidewalk, between the kerb and the building line, and no road
    // user comes near it at any frame (footprints apart by half their diagonals' sum).
    let half_diagonal = |s: [f64; 3]| 0.5 * s[0].hypot(s[1]);
    let (kerb, building) = (
        config.street.road_half_width,
        config.street.road_half_width + config.street.sidewalk_width,
    );
    for p in &street.clutter {
        let on_sidewalk = street.segments.iter().any(|s| {
            let (dx, dy) = (p.centre[0] - s.point[0], p.centre[1] - s.point[1]);
            let along = dx * s.dir[0] + dy * s.dir[1];
            let l = s.left();
            let lateral = (dx * l[0] + dy * l[1]).abs();
            (s.s_start..=s.s_end).contains(&along)
                && lateral - 0.5 * p.size[1] >= kerb - 1e-9
                && lateral + 0.5 * p.size[1] <= building + 1e-9
        });
        assert!(on_sidewalk, "{p:?}");
        for k in 0..sim.frames() {
            for o in &street.objects {
                if let Some((q, _)) = o.state_at(&street.segments, sim.time(k)) {
                    let d = (q[0] - p.centre[0]).hypot(q[1] - p.centre[1]);
                    // A long hedge's diagonal overstates its half-width; test across it.
                    let across = if p.size[0] > 2.0 * p.size[1] {
                        0.5 * p.size[1]
                    } else {
                        half_diagonal(p.size)
                    };
                    let near = d < across + 0.5 * o.size[1].min(o.size[0]) - 1e-9;
                    assert!(!near, "object {} meets {p:?} at frame {k}", o.id);
                }
            }
        }
    }
    // The scans see the clutter; a hedge's returns scatter into it, a low wall's do not.
    let truth = sim.truth();
    assert_eq!(truth.clutter, street.clutter);
    let mut depth: std::collections::HashMap<u32, Vec<f64>> = Default::default();
    for k in [10, 30, 50] {
        let scan = sim.scan(k);
        let pose = sim.velodyne_pose(k);
        for (i, s) in scan.surfaces.iter().enumerate() {
            if let Surface::Clutter(id) = *s {
                let piece = &street.clutter[id as usize];
                let p = scan.cloud.get(i).unwrap();
                let w = pose * Point3::new(p.x as f64, p.y as f64, p.z as f64);
                // Returns through the long faces only (not the top or the ends): their depth
                // behind the face they entered, across the street.
                let (u, n) = (
                    [piece.yaw.cos(), piece.yaw.sin()],
                    [-piece.yaw.sin(), piece.yaw.cos()],
                );
                let (dx, dy) = (w.x - piece.centre[0], w.y - piece.centre[1]);
                let along = dx * u[0] + dy * u[1];
                let off = dx * n[0] + dy * n[1];
                // Shapes stand on z = 0 whatever the ground's relief.
                let side_face =
                    along.abs() < 0.5 * piece.size[0] - 0.4 && w.z < piece.size[2] - 0.4;
                if side_face {
                    depth
                        .entry(id)
                        .or_default()
                        .push(0.5 * piece.size[1] - off.abs());
                }
            }
        }
    }
    assert!(!depth.is_empty(), "no clutter in view");
    let spread = |kind: ClutterKind| -> Option<f64> {
        let all: Vec<f64> = street
            .clutter
            .iter()
            .filter(|p| p.kind == kind)
            .filter_map(|p| depth.get(&p.id))
            .flatten()
            .copied()
            .collect();
        (all.len() > 20).then(|| {
            let mean = all.iter().sum::<f64>() / all.len() as f64;
            (all.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / all.len() as f64).sqrt()
        })
    };
    // Uniform over 0.3 m: σ ≈ 0.087 m (with 0.02 m range noise); a solid face: about the noise.
    let hedge = spread(ClutterKind::Hedge).expect("hedges in view");
    assert!((0.06..0.12).contains(&hedge), "hedge depth spread {hedge}");
    if let Some(wall) = spread(ClutterKind::LowWall) {
        assert!(wall < 0.05, "low wall depth spread {wall}");
    }
}

#[test]
fn the_plain_street_has_no_clutter_and_its_objects_do_not_move_when_other_kinds_are_added() {
    let plain = StreetSimulator::new(&StreetConfig::default(), 60, 5).unwrap();
    assert!(plain.street().clutter.is_empty());
    let mut more = StreetConfig::default();
    more.traffic.cyclists = 2;
    more.traffic.moving_vans = 1;
    let sim = StreetSimulator::new(&more, 60, 5).unwrap();
    let n = plain.street().objects.len();
    assert_eq!(&sim.street().objects[..n], &plain.street().objects[..]);
    assert_eq!(sim.street().walls, plain.street().walls);
    assert_eq!(sim.street().objects.len(), n + 3);
    // The plain sidewalk is too narrow for poles beside its walkers.
    more.clutter.poles = 3;
    let err = more.validate().unwrap_err().to_string();
    assert!(err.contains("clutter.poles"), "{err}");
    // Clutter comes after the road users: more of it moves none of them.
    let urban = StreetConfig::urban();
    let mut more_poles = urban.clone();
    more_poles.clutter.poles += 2;
    let (a, b) = (
        StreetSimulator::new(&urban, 60, 5).unwrap(),
        StreetSimulator::new(&more_poles, 60, 5).unwrap(),
    );
    assert_eq!(a.street().objects, b.street().objects);
    assert_eq!(a.street().walls, b.street().walls);
    assert_eq!(b.street().clutter.len(), a.street().clutter.len() + 2);
}

#[test]
fn parked_rows_stand_nose_to_tail_and_hide_one_another() {
    let config = StreetConfig::parked_rows();
    config.validate().unwrap();
    // The preset's config is written with its rows; the others' without the field.
    let json = serde_json::to_string(&config).unwrap();
    assert!(json.contains("parked_rows"));
    assert_eq!(serde_json::from_str::<StreetConfig>(&json).unwrap(), config);
    for plain in [StreetConfig::default(), StreetConfig::urban()] {
        assert!(!serde_json::to_string(&plain)
            .unwrap()
            .contains("parked_rows"));
    }
    let run = generate(&config, 20, 3).unwrap();
    let sim = StreetSimulator::new(&config, 20, 3).unwrap();
    let street = sim.street();
    let parked: Vec<&world::Object> = street
        .objects
        .iter()
        .filter(|o| o.kind.is_parked())
        .collect();
    assert!(parked.len() > 20, "{}", parked.len());
    assert!(parked.iter().any(|o| o.kind == ObjectKind::ParkedVan));
    // Along each kerb of each segment, the gaps between neighbours' bumpers: never below
    // 0.5 m, and mostly (bar openings and stretches beyond the spawn radius) within 2 m.
    let (mut gaps, mut short) = (0, 0);
    for j in 0..street.segments.len() {
        for side in [-1.0, 1.0] {
            let mut row: Vec<(f64, f64)> = parked
                .iter()
                .filter(|o| o.segment == j && o.lateral * side > 0.0)
                .map(|o| (o.s0, o.size[0]))
                .collect();
            row.sort_by(|a, b| a.0.total_cmp(&b.0));
            for w in row.windows(2) {
                let gap = (w[1].0 - 0.5 * w[1].1) - (w[0].0 + 0.5 * w[0].1);
                assert!(gap >= 0.5 - 1e-9, "segment {j}: gap {gap}");
                gaps += 1;
                short += usize::from(gap <= 2.0 + 1e-9);
            }
        }
    }
    assert!(
        gaps > 20 && short * 10 >= gaps * 7,
        "{short} of {gaps} gaps within 2 m"
    );
    // Every level occurs among the parked vehicles seen; the hidden shares lie in [0, 1].
    let mut levels = [0usize; 4];
    for o in run.truth.objects.iter().filter(|o| o.kind.is_parked()) {
        for s in &o.states {
            assert!(s.hidden_rays <= s.rays, "{s:?}");
            assert_eq!(s.occluded, occlusion_level(s.hidden_share()));
            if s.points > 0 {
                levels[s.occluded as usize] += 1;
            }
        }
    }
    assert!(
        levels[0] > 0 && levels[1] > 0 && levels[2] > 0,
        "{levels:?}"
    );
}
