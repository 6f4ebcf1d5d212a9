--
-- PostgreSQL database dump
--


-- Dumped from database version 15.18 (Debian 15.18-0+deb12u1)
-- Dumped by pg_dump version 15.18 (Debian 15.18-0+deb12u1)

SET statement_timeout = 0;
SET lock_timeout = 0;
SET idle_in_transaction_session_timeout = 0;
SET client_encoding = 'UTF8';
SET standard_conforming_strings = on;
SELECT pg_catalog.set_config('search_path', '', false);
SET check_function_bodies = false;
SET xmloption = content;
SET client_min_messages = warning;
SET row_security = off;

--
-- Name: public; Type: SCHEMA; Schema: -; Owner: -
--

-- *not* creating schema, since initdb creates it


SET default_tablespace = '';

SET default_table_access_method = heap;

--
-- Name: interval_decisions; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.interval_decisions (
    id integer NOT NULL,
    run_id character varying(32),
    interval_id integer NOT NULL,
    decision character varying(16) NOT NULL,
    note text NOT NULL,
    reviewer character varying(255) NOT NULL,
    client character varying(255) NOT NULL,
    created_at timestamp with time zone NOT NULL
);


--
-- Name: interval_decisions_id_seq; Type: SEQUENCE; Schema: public; Owner: -
--

CREATE SEQUENCE public.interval_decisions_id_seq
    AS integer
    START WITH 1
    INCREMENT BY 1
    NO MINVALUE
    NO MAXVALUE
    CACHE 1;


--
-- Name: interval_decisions_id_seq; Type: SEQUENCE OWNED BY; Schema: public; Owner: -
--

ALTER SEQUENCE public.interval_decisions_id_seq OWNED BY public.interval_decisions.id;


--
-- Name: reviews; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.reviews (
    id integer NOT NULL,
    take_id character varying(32),
    status character varying(16) NOT NULL,
    notes text NOT NULL,
    reviewer character varying(255) NOT NULL,
    created_at timestamp with time zone NOT NULL
);


--
-- Name: reviews_id_seq; Type: SEQUENCE; Schema: public; Owner: -
--

CREATE SEQUENCE public.reviews_id_seq
    AS integer
    START WITH 1
    INCREMENT BY 1
    NO MINVALUE
    NO MAXVALUE
    CACHE 1;


--
-- Name: reviews_id_seq; Type: SEQUENCE OWNED BY; Schema: public; Owner: -
--

ALTER SEQUENCE public.reviews_id_seq OWNED BY public.reviews.id;


--
-- Name: runs; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.runs (
    id character varying(32) NOT NULL,
    take_id character varying(32),
    status character varying(16) NOT NULL,
    progress integer NOT NULL,
    step character varying(255) NOT NULL,
    options json NOT NULL,
    input_sha256 character varying(64) NOT NULL,
    version character varying(32) NOT NULL,
    error text,
    summary json,
    server_time_s double precision,
    created_at timestamp with time zone NOT NULL,
    started_at timestamp with time zone,
    finished_at timestamp with time zone,
    attempts integer DEFAULT 0 NOT NULL
);


--
-- Name: shoots; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.shoots (
    id character varying(32) NOT NULL,
    name character varying(255) NOT NULL,
    created_at timestamp with time zone NOT NULL
);


--
-- Name: source_hashes; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.source_hashes (
    path character varying(1024) NOT NULL,
    size_bytes bigint NOT NULL,
    mtime_ns bigint NOT NULL,
    sha256 character varying(64) NOT NULL
);


--
-- Name: take_qa; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.take_qa (
    take_id character varying(32) NOT NULL,
    shoot_id character varying(32),
    name character varying(255) NOT NULL,
    kind character varying(16) NOT NULL,
    created_at timestamp with time zone NOT NULL,
    run_id character varying(32),
    status character varying(16),
    review_status character varying(16) NOT NULL,
    reviewer character varying(255),
    score double precision,
    n_frames integer,
    duration_s double precision,
    rig character varying(64),
    twist_intervals integer,
    corrected_joint_frames integer,
    violation_share double precision,
    worst_joint character varying(255),
    filter_residual_mm double precision,
    missing_share double precision,
    n_findings integer,
    joint_violations json
);


--
-- Name: takes; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.takes (
    id character varying(32) NOT NULL,
    name character varying(255) NOT NULL,
    format character varying(32) NOT NULL,
    kind character varying(16) NOT NULL,
    size_bytes bigint NOT NULL,
    sha256 character varying(64) NOT NULL,
    n_frames integer NOT NULL,
    fps double precision NOT NULL,
    n_joints integer NOT NULL,
    file_name character varying(255) NOT NULL,
    created_at timestamp with time zone NOT NULL,
    shoot_id character varying(32)
);


--
-- Name: interval_decisions id; Type: DEFAULT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.interval_decisions ALTER COLUMN id SET DEFAULT nextval('public.interval_decisions_id_seq'::regclass);


--
-- Name: reviews id; Type: DEFAULT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.reviews ALTER COLUMN id SET DEFAULT nextval('public.reviews_id_seq'::regclass);


--
-- Data for Name: interval_decisions; Type: TABLE DATA; Schema: public; Owner: -
--



--
-- Data for Name: reviews; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.reviews VALUES (1, '7408df690b1f4b928a5f0d2ac84b351d', 'needs_fix', 'left leg pops', 'ann', '2026-12-01 23:35:08.535384+00');
INSERT INTO public.reviews VALUES (2, '7408df690b1f4b928a5f0d2ac84b351d', 'approved', 'fixed', 'bo', '2026-12-01 23:35:08.601238+00');


--
-- Data for Name: runs; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.runs VALUES ('3e0f0aef4efe48ff912ca2932ff206c9', 'c3e82262f43a491990faa2c58a00d2e1', 'done', 100, 'done', '{"checks": ["twist", "limits", "filter"], "twist_method": "robust", "twist_apply": "confident", "filter_method": null, "filter_preset": null, "filter_params": {}, "max_points": 2000, "mapping": {}}', 'dd6988f41b55162ee97efcb900f10d254734a5987b80534a80c7cec5406f228a', '0.1.0', NULL, '{"n_frames": 25, "fps": 30.000030000029998, "duration_s": 0.8333325, "n_joints": 18, "length_unit": "unknown", "root_translation": "replace", "roles": {"left_clavicle": "LeftShoulder", "left_foot": "LeftFoot", "left_forearm": "LeftForeArm", "left_hand": "LeftHand", "left_lower_leg": "LeftLeg", "left_upper_arm": "LeftArm", "left_upper_leg": "LeftUpLeg", "right_clavicle": "RightShoulder", "right_foot": "RightFoot", "right_forearm": "RightForeArm", "right_hand": "RightHand", "right_lower_leg": "RightLeg", "right_upper_arm": "RightArm", "right_upper_leg": "RightUpLeg"}, "missing_roles": ["left_toe", "right_toe"], "n_findings": 6, "findings_by_kind": {"limits": 6}, "steps": {"twist": "done", "limits": "done", "filter": "skipped"}, "qa": {"n_frames": 25, "duration_s": 0.8333, "rig": "cmu", "twist_intervals": 0, "corrected_joint_frames": 0, "violation_share": 1.0, "worst_joint": "RightHand", "filter_residual_mm": null, "missing_share": 0.0, "joint_violations": {"LeftArm": 0.76, "LeftForeArm": 0.36, "LeftHand": 1.0, "RightArm": 0.4, "RightHand": 1.0}, "score": 61.9}}', 0.46872639100001834, '2026-12-01 23:35:07.428936+00', '2026-12-01 23:35:07.471478+00', '2026-12-01 23:35:07.94052+00', 1);
INSERT INTO public.runs VALUES ('d5ecab55fc8c43f6b78699e9dcd5db1a', 'a56674b112e644e7b6c0c3de55f46d68', 'done', 100, 'done', '{"checks": ["twist", "limits", "filter"], "twist_method": "robust", "twist_apply": "confident", "filter_method": null, "filter_preset": null, "filter_params": {}, "max_points": 2000, "mapping": {}}', 'eddb26d2c8ce431e50898407213d0bd0e49af8db03f1b3f9dc022cfe4855ec3f', '0.1.0', NULL, '{"n_frames": 30, "fps": 30.000030000029998, "duration_s": 0.9999990000000001, "n_joints": 18, "length_unit": "unknown", "root_translation": "replace", "roles": {"left_clavicle": "LeftShoulder", "left_foot": "LeftFoot", "left_forearm": "LeftForeArm", "left_hand": "LeftHand", "left_lower_leg": "LeftLeg", "left_upper_arm": "LeftArm", "left_upper_leg": "LeftUpLeg", "right_clavicle": "RightShoulder", "right_foot": "RightFoot", "right_forearm": "RightForeArm", "right_hand": "RightHand", "right_lower_leg": "RightLeg", "right_upper_arm": "RightArm", "right_upper_leg": "RightUpLeg"}, "missing_roles": ["left_toe", "right_toe"], "n_findings": 8, "findings_by_kind": {"limits": 8}, "steps": {"twist": "done", "limits": "done", "filter": "skipped"}, "qa": {"n_frames": 30, "duration_s": 1.0, "rig": "cmu", "twist_intervals": 0, "corrected_joint_frames": 0, "violation_share": 1.0, "worst_joint": "RightHand", "filter_residual_mm": null, "missing_share": 0.0, "joint_violations": {"LeftArm": 0.866667, "LeftForeArm": 0.133333, "LeftHand": 1.0, "RightArm": 0.466667, "RightHand": 1.0}, "score": 61.9}}', 0.3490682810006547, '2026-12-01 23:35:08.923038+00', '2026-12-01 23:35:08.939673+00', '2026-12-01 23:35:09.285995+00', 1);
INSERT INTO public.runs VALUES ('a2790a977247453bacbf93de9307636d', '7408df690b1f4b928a5f0d2ac84b351d', 'done', 100, 'done', '{"checks": ["twist", "limits", "filter"], "twist_method": "robust", "twist_apply": "confident", "filter_method": null, "filter_preset": null, "filter_params": {}, "max_points": 2000, "mapping": {}}', 'bc105caaff9beb22ad067d2e4764c349af7748669b4e2d66b8dde1e5392f4896', '0.1.0', NULL, '{"n_frames": 24, "fps": 30.000030000029998, "duration_s": 0.7999992, "n_joints": 18, "length_unit": "unknown", "root_translation": "replace", "roles": {"left_clavicle": "LeftShoulder", "left_foot": "LeftFoot", "left_forearm": "LeftForeArm", "left_hand": "LeftHand", "left_lower_leg": "LeftLeg", "left_upper_arm": "LeftArm", "left_upper_leg": "LeftUpLeg", "right_clavicle": "RightShoulder", "right_foot": "RightFoot", "right_forearm": "RightForeArm", "right_hand": "RightHand", "right_lower_leg": "RightLeg", "right_upper_arm": "RightArm", "right_upper_leg": "RightUpLeg"}, "missing_roles": ["left_toe", "right_toe"], "n_findings": 5, "findings_by_kind": {"limits": 5}, "steps": {"twist": "done", "limits": "done", "filter": "skipped"}, "qa": {"n_frames": 24, "duration_s": 0.8, "rig": "cmu", "twist_intervals": 0, "corrected_joint_frames": 0, "violation_share": 1.0, "worst_joint": "RightHand", "filter_residual_mm": null, "missing_share": 0.0, "joint_violations": {"LeftArm": 1.0, "LeftForeArm": 1.0, "LeftHand": 1.0, "RightArm": 0.833333, "RightHand": 1.0}, "score": 61.9}}', 10.749548363999565, '2026-12-01 23:34:56.568641+00', '2026-12-01 23:34:56.624616+00', '2026-12-01 23:35:07.374201+00', 1);
INSERT INTO public.runs VALUES ('864d23811559408dbb9801410a2ef6c4', '7408df690b1f4b928a5f0d2ac84b351d', 'done', 100, 'done', '{"checks": ["limits"], "twist_method": "robust", "twist_apply": "confident", "filter_method": null, "filter_preset": null, "filter_params": {}, "max_points": 2000, "mapping": {}}', 'bc105caaff9beb22ad067d2e4764c349af7748669b4e2d66b8dde1e5392f4896', '0.1.0', NULL, '{"n_frames": 24, "fps": 30.000030000029998, "duration_s": 0.7999992, "n_joints": 18, "length_unit": "unknown", "root_translation": "replace", "roles": {"left_clavicle": "LeftShoulder", "left_foot": "LeftFoot", "left_forearm": "LeftForeArm", "left_hand": "LeftHand", "left_lower_leg": "LeftLeg", "left_upper_arm": "LeftArm", "left_upper_leg": "LeftUpLeg", "right_clavicle": "RightShoulder", "right_foot": "RightFoot", "right_forearm": "RightForeArm", "right_hand": "RightHand", "right_lower_leg": "RightLeg", "right_upper_arm": "RightArm", "right_upper_leg": "RightUpLeg"}, "missing_roles": ["left_toe", "right_toe"], "n_findings": 5, "findings_by_kind": {"limits": 5}, "steps": {"twist": "skipped", "limits": "done", "filter": "skipped"}, "qa": {"n_frames": 24, "duration_s": 0.8, "rig": "cmu", "twist_intervals": null, "corrected_joint_frames": null, "violation_share": 1.0, "worst_joint": "RightHand", "filter_residual_mm": null, "missing_share": 0.0, "joint_violations": {"LeftArm": 1.0, "LeftForeArm": 1.0, "LeftHand": 1.0, "RightArm": 0.833333, "RightHand": 1.0}, "score": 61.9}}', 0.3365711269998428, '2026-12-01 23:35:08.047399+00', '2026-12-01 23:35:08.079465+00', '2026-12-01 23:35:08.415543+00', 1);


--
-- Data for Name: shoots; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.shoots VALUES ('8f0a1283cbe34d349ad71e4f78e4b052', 'day 1', '2026-12-01 23:35:08.787981+00');


--
-- Data for Name: source_hashes; Type: TABLE DATA; Schema: public; Owner: -
--



--
-- Data for Name: take_qa; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.take_qa VALUES ('c3e82262f43a491990faa2c58a00d2e1', NULL, 'walk_b.bvh', 'motion', '2026-12-01 23:35:07.427548+00', '3e0f0aef4efe48ff912ca2932ff206c9', 'done', 'unreviewed', NULL, 61.9, 25, 0.8333, 'cmu', 0, 0, 1, 'RightHand', NULL, 0, 6, '{"LeftArm": 0.76, "LeftForeArm": 0.36, "LeftHand": 1.0, "RightArm": 0.4, "RightHand": 1.0}');
INSERT INTO public.take_qa VALUES ('7408df690b1f4b928a5f0d2ac84b351d', NULL, 'walk_a.bvh', 'motion', '2026-12-01 23:34:56.553389+00', '864d23811559408dbb9801410a2ef6c4', 'done', 'approved', 'bo', 61.9, 24, 0.8, 'cmu', NULL, NULL, 1, 'RightHand', NULL, 0, 5, '{"LeftArm": 1.0, "LeftForeArm": 1.0, "LeftHand": 1.0, "RightArm": 0.833333, "RightHand": 1.0}');
INSERT INTO public.take_qa VALUES ('a56674b112e644e7b6c0c3de55f46d68', '8f0a1283cbe34d349ad71e4f78e4b052', 'shoot_c.bvh', 'motion', '2026-12-01 23:35:08.921426+00', 'd5ecab55fc8c43f6b78699e9dcd5db1a', 'done', 'unreviewed', NULL, 61.9, 30, 1, 'cmu', 0, 0, 1, 'RightHand', NULL, 0, 8, '{"LeftArm": 0.866667, "LeftForeArm": 0.133333, "LeftHand": 1.0, "RightArm": 0.466667, "RightHand": 1.0}');


--
-- Data for Name: takes; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.takes VALUES ('7408df690b1f4b928a5f0d2ac84b351d', 'walk_a.bvh', 'bvh', 'motion', 12142, 'bc105caaff9beb22ad067d2e4764c349af7748669b4e2d66b8dde1e5392f4896', 24, 30.000030000029998, 18, 'walk_a.bvh', '2026-12-01 23:34:56.553389+00', NULL);
INSERT INTO public.takes VALUES ('c3e82262f43a491990faa2c58a00d2e1', 'walk_b.bvh', 'bvh', 'motion', 12633, 'dd6988f41b55162ee97efcb900f10d254734a5987b80534a80c7cec5406f228a', 25, 30.000030000029998, 18, 'walk_b.bvh', '2026-12-01 23:35:07.427548+00', NULL);
INSERT INTO public.takes VALUES ('a56674b112e644e7b6c0c3de55f46d68', 'shoot_c.bvh', 'bvh', 'motion', 14696, 'eddb26d2c8ce431e50898407213d0bd0e49af8db03f1b3f9dc022cfe4855ec3f', 30, 30.000030000029998, 18, 'shoot_c.bvh', '2026-12-01 23:35:08.921426+00', '8f0a1283cbe34d349ad71e4f78e4b052');


--
-- Name: interval_decisions_id_seq; Type: SEQUENCE SET; Schema: public; Owner: -
--

SELECT pg_catalog.setval('public.interval_decisions_id_seq', 1, false);


--
-- Name: reviews_id_seq; Type: SEQUENCE SET; Schema: public; Owner: -
--

SELECT pg_catalog.setval('public.reviews_id_seq', 2, true);


--
-- Name: interval_decisions interval_decisions_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.interval_decisions
    ADD CONSTRAINT interval_decisions_pkey PRIMARY KEY (id);


--
-- Name: reviews reviews_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.reviews
    ADD CONSTRAINT reviews_pkey PRIMARY KEY (id);


--
-- Name: runs runs_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.runs
    ADD CONSTRAINT runs_pkey PRIMARY KEY (id);


--
-- Name: shoots shoots_name_key; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.shoots
    ADD CONSTRAINT shoots_name_key UNIQUE (name);


--
-- Name: shoots shoots_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.shoots
    ADD CONSTRAINT shoots_pkey PRIMARY KEY (id);


--
-- Name: source_hashes source_hashes_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.source_hashes
    ADD CONSTRAINT source_hashes_pkey PRIMARY KEY (path);


--
-- Name: take_qa take_qa_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.take_qa
    ADD CONSTRAINT take_qa_pkey PRIMARY KEY (take_id);


--
-- Name: takes takes_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.takes
    ADD CONSTRAINT takes_pkey PRIMARY KEY (id);


--
-- Name: ix_interval_decisions_run_id; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_interval_decisions_run_id ON public.interval_decisions USING btree (run_id);


--
-- Name: ix_reviews_take_id; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_reviews_take_id ON public.reviews USING btree (take_id);


--
-- Name: ix_runs_status; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_runs_status ON public.runs USING btree (status);


--
-- Name: ix_runs_take_id; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_runs_take_id ON public.runs USING btree (take_id);


--
-- Name: ix_take_qa_shoot_created; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_take_qa_shoot_created ON public.take_qa USING btree (shoot_id, created_at);


--
-- Name: ix_take_qa_shoot_name; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_take_qa_shoot_name ON public.take_qa USING btree (shoot_id, name);


--
-- Name: ix_take_qa_shoot_review; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_take_qa_shoot_review ON public.take_qa USING btree (shoot_id, review_status);


--
-- Name: ix_take_qa_shoot_score; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_take_qa_shoot_score ON public.take_qa USING btree (shoot_id, score);


--
-- Name: ix_take_qa_shoot_status; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_take_qa_shoot_status ON public.take_qa USING btree (shoot_id, status);


--
-- Name: ix_takes_shoot_id; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_takes_shoot_id ON public.takes USING btree (shoot_id);


--
-- Name: interval_decisions interval_decisions_run_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.interval_decisions
    ADD CONSTRAINT interval_decisions_run_id_fkey FOREIGN KEY (run_id) REFERENCES public.runs(id) ON DELETE CASCADE;


--
-- Name: reviews reviews_take_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.reviews
    ADD CONSTRAINT reviews_take_id_fkey FOREIGN KEY (take_id) REFERENCES public.takes(id) ON DELETE CASCADE;


--
-- Name: runs runs_take_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.runs
    ADD CONSTRAINT runs_take_id_fkey FOREIGN KEY (take_id) REFERENCES public.takes(id) ON DELETE CASCADE;


--
-- Name: take_qa take_qa_take_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.take_qa
    ADD CONSTRAINT take_qa_take_id_fkey FOREIGN KEY (take_id) REFERENCES public.takes(id) ON DELETE CASCADE;


--
-- Name: takes takes_shoot_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.takes
    ADD CONSTRAINT takes_shoot_id_fkey FOREIGN KEY (shoot_id) REFERENCES public.shoots(id);


--
-- PostgreSQL database dump complete
--


